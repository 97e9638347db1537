#pragma once
// Evaluates a layout's sampleVolume() on the GPU at positions chosen by the
// caller and reads the results back as floats: the tool that checks every
// layout's address maths against direct indexing (DESIGN.md, Testing) and
// layouts against each other.
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/gpu/GlContext.h"
#include "tessera/layout/Layout.h"

namespace tessera::layout {

class LayoutProbe {
 public:
  explicit LayoutProbe(gpu::GlContext& context) : context_(context) {}

  // Stored values (before rawFromStored()) at `positions` in [0,1]^3.
  // Needs float render targets (EXT_color_buffer_float); GpuError otherwise.
  std::vector<float> sample(const Layout& layout, const std::vector<glm::vec3>& positions);

  // The positions of every voxel centre, x fastest: ((i + 0.5) / dims).
  static std::vector<glm::vec3> voxelCentres(glm::ivec3 dims);

 private:
  gpu::GlContext& context_;
};

}  // namespace tessera::layout
