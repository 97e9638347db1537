#pragma once
// The volume in one 3D texture (ES 3.0 / WebGL 2), hardware trilinear
// filtering. u8 volumes are stored as R8; other types are normalised over
// their value range into 16 bits (R16 with EXT_texture_norm16, else R16F).
#include <memory>

#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/MemoryLedger.h"
#include "tessera/layout/Layout.h"
#include "tessera/layout/LayoutRegistry.h"

namespace tessera::layout {

class Texture3DLayout final : public Layout {
 public:
  // What the layout would allocate for `volume` within `limits`;
  // plan.fits and plan.reason say whether and why (not).
  static LayoutPlan planFor(const Volume& volume, const gpu::DeviceLimits& limits);

  // Plans and uploads. Throws GpuError if the plan does not fit.
  static std::unique_ptr<Texture3DLayout> create(const Volume& volume,
                                                 const gpu::DeviceLimits& limits,
                                                 gpu::MemoryLedger& ledger);

  std::string name() const override { return "texture3d"; }
  const LayoutPlan& plan() const override { return plan_; }
  gpu::ShaderPart glsl() const override;
  int bind(const gpu::Program& program, int firstUnit) const override;
  ValueMapping rawFromStored() const override { return mapping_; }
  glm::ivec3 volumeDims() const override { return dims_; }
  std::uint64_t textureBytes() const override { return texture_.bytes(); }
  int textureUnits() const override { return 1; }

  // The planner's entry: needs 3D textures (ES 3), costs planFor().
  static LayoutEntry registration();

 private:
  Texture3DLayout() = default;
  LayoutPlan plan_;
  gpu::Texture texture_;
  ValueMapping mapping_;
  glm::ivec3 dims_{0};
};

}  // namespace tessera::layout
