#pragma once
// Texture slicing (view-aligned Slice3DRenderer or axis-aligned
// Slice2DRenderer) as a HybridTechnique: the compositor samples the
// slicer's own resolved colour texture, nothing is read back.
//
// The slicers have no view-aspect override (their projection always fills
// the target), so a target of another shape than the screen (128x128 for a
// 480x640 screen) is rendered with the same number of pixels in the
// screen's shape (111x148): the same fragment cost, and no stretching.
#include <algorithm>
#include <cmath>
#include <string>

#include <glm/vec2.hpp>

#include "tessera/render/HybridTechnique.h"

namespace tessera::render {

// The target a slicer renders for a requested width x height and screen
// aspect (screen width / height): that size when it has the screen's shape,
// else the same pixel count in the screen's shape.
inline glm::ivec2 sliceTargetSize(int width, int height, double viewAspect) {
  if (std::abs(static_cast<double>(width) / height - viewAspect) <= 1e-3 * viewAspect) {
    return {width, height};
  }
  const double pixels = static_cast<double>(width) * height;
  return {std::max(1, static_cast<int>(std::lround(std::sqrt(pixels * viewAspect)))),
          std::max(1, static_cast<int>(std::lround(std::sqrt(pixels / viewAspect))))};
}

template <class Slicer>
class HybridSliceTechnique : public HybridTechnique {
 public:
  // `slicer` must outlive this adapter; its TF and slice count are used.
  HybridSliceTechnique(std::string name, Slicer& slicer)
      : name_(std::move(name)), slicer_(slicer) {}

  std::string name() const override { return name_; }
  const gpu::Texture& renderVolume(const Camera& camera, const RenderSettings& settings, int width,
                                   int height, double viewAspect) override {
    const glm::ivec2 size = sliceTargetSize(width, height, viewAspect);
    slicer_.renderFrame(camera, settings, size.x, size.y);
    return slicer_.colorTexture();
  }

 private:
  std::string name_;
  Slicer& slicer_;
};

}  // namespace tessera::render
