#pragma once
// Evaluates a layout's sampleVolume() on the GPU at positions chosen by the
// caller and reads the results back as floats: the tool that checks every
// layout's address maths against direct indexing (DESIGN.md, Testing) and
// layouts against each other.
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "tessera/gpu/GlContext.h"
#include "tessera/layout/Layout.h"

namespace tessera::layout {

class LayoutProbe {
 public:
  explicit LayoutProbe(gpu::GlContext& context) : context_(context) {}

  // Stored values (before rawFromStored()) at `positions` in [0,1]^3.
  // With float render targets (ES 3 + EXT_color_buffer_float) the values
  // come back as floats, exactly. Without them (every ES 2 context) each
  // position is drawn as a one-pixel point carrying it as a float vertex
  // attribute, and the value v in [0,1] (clamped) is written to an RGBA8
  // target in two channels, hi = floor(255 v) / 255 and lo = fract(255 v),
  // and decoded as (255 hi + lo) / 255: exact to 0.5 / 65025.
  std::vector<float> sample(const Layout& layout, const std::vector<glm::vec3>& positions);

  // sampleVolumeGradient() (rgb, stored value per texture-space unit) and
  // sampleVolume() (a) of the layout seam at `positions`. Needs float render
  // targets (GpuError otherwise: see hasFloatTargets()).
  std::vector<glm::vec4> sampleGradient(const Layout& layout,
                                        const std::vector<glm::vec3>& positions);
  bool hasFloatTargets() const;

  // The positions of every voxel centre, x fastest: ((i + 0.5) / dims).
  static std::vector<glm::vec3> voxelCentres(glm::ivec3 dims);

  // Largest error of a value read back through the RGBA8 encoding.
  static constexpr double kRgba8Error = 0.5 / 65025.0;

 private:
  std::vector<glm::vec4> probeFloat(const Layout& layout, const std::vector<glm::vec3>& positions,
                                    bool gradient);
  std::vector<float> sampleRgba8(const Layout& layout, const std::vector<glm::vec3>& positions);
  gpu::GlContext& context_;
};

}  // namespace tessera::layout
