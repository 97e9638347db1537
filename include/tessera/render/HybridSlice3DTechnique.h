#pragma once
// View-aligned texture slicing (Slice3DRenderer) as a HybridTechnique. The
// slicer renders into its own target and exposes only a read-back, so the
// frame is read back and uploaded into a texture, as Moser & Weiskopf did on
// devices without pbuffer textures. It has no view-aspect override either: a
// target of another shape than the screen (128x128 for 480x640) is rendered
// with the same number of pixels in the screen's shape (111x148), which costs
// the same fragments and needs no stretching.
#include <memory>

#include "tessera/gpu/GlContext.h"
#include "tessera/render/HybridTechnique.h"
#include "tessera/render/Slice3DRenderer.h"

namespace tessera::render {

class HybridSlice3DTechnique : public HybridTechnique {
 public:
  // `slicer` must outlive this adapter.
  HybridSlice3DTechnique(gpu::GlContext& context, Slice3DRenderer& slicer)
      : context_(context), slicer_(slicer) {}

  std::string name() const override { return "slice3d"; }
  const gpu::Texture& renderVolume(const Camera& camera, const RenderSettings& settings, int width,
                                   int height, double viewAspect) override;

 private:
  gpu::GlContext& context_;
  Slice3DRenderer& slicer_;
  gpu::Texture texture_;
};

}  // namespace tessera::render
