#pragma once
// The ray caster as a HybridTechnique.
#include "tessera/render/HybridTechnique.h"
#include "tessera/render/Raycaster.h"

namespace tessera::render {

class HybridRaycastTechnique : public HybridTechnique {
 public:
  // `caster` must outlive this adapter; its TF and skipping settings are used.
  explicit HybridRaycastTechnique(Raycaster& caster) : caster_(caster) {}

  std::string name() const override { return "raycast"; }
  const gpu::Texture& renderVolume(const Camera& camera, const RenderSettings& settings, int width,
                                   int height, double viewAspect) override {
    caster_.setViewAspect(viewAspect);
    caster_.renderFrame(camera, settings, width, height);
    caster_.setViewAspect(0.0);
    return caster_.colorTexture();
  }

 private:
  Raycaster& caster_;
};

}  // namespace tessera::render
