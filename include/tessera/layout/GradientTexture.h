#pragma once
// The shading gradient precomputed into a texture, or taken on the fly
// (docs/shading.md). On the fly: central differences through sampleVolume(),
// 6 extra fetches per lit sample (layout/gradient.glsl), no memory, every
// layout and API. Precomputed: the per-voxel differences of
// reference/VoxelGradients.h in an RGBA8 3D texture (4 bytes per voxel), one
// fetch per lit sample; it needs ES 3's 3D textures and room in the budget,
// and stands in for the seam's gradient on any Cartesian trilinear layout
// (their sampleVolume() puts voxel centres at (i + 0.5) / dims, as the
// texture does).
#include <cstdint>
#include <string>

#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/Program.h"
#include "tessera/layout/Layout.h"
#include "tessera/reference/VoxelGradients.h"

namespace tessera::layout {

// --gradient: auto (the plan's choice), on-the-fly, or precomputed (an error
// where it cannot be had).
enum class GradientWish { Auto, OnTheFly, Precomputed };
GradientWish parseGradientWish(const std::string& text);

struct GradientPlan {
  bool precomputed = false;
  PlannedTexture texture;  // what a precomputed gradient allocates (planned either way)
  std::string reason;      // one line: the choice and why
};

// The choice for a volume of `dims` on `layoutName` in a context of `api`
// (max3DTextureSize 0: no 3D textures) whose budget (0 = unlimited) has
// `bytesInUse` taken. Throws InputError when `wish` is Precomputed and it
// cannot be had.
GradientPlan planGradient(GradientWish wish, glm::ivec3 dims, const std::string& layoutName,
                          gpu::ApiLevel api, int max3DTextureSize, std::uint64_t budget,
                          std::uint64_t bytesInUse);

// The uploaded texture and the CPU field it holds (the reference shades with
// the same, VoxelGradientReconstruction).
class GradientTexture {
 public:
  GradientTexture() = default;
  static GradientTexture create(gpu::MemoryLedger& ledger, const Volume& volume);
  bool valid() const { return texture_.id() != 0; }
  const VoxelGradients& gradients() const { return gradients_; }
  // Binds the texture to `unit` and sets the GLSL part's uniforms
  // (layout/gradient_texture.glsl); `rawPerStored` is the layout's
  // rawFromStored().scale. Returns the units used (1).
  int bind(const gpu::Program& program, int unit, double rawPerStored) const;
  std::uint64_t bytes() const { return valid() ? gradients_.texels.size() : 0; }
  // Whether the texture's alpha holds the voxels' raw values (8-bit volumes):
  // sampleVolumeAndGradient() may stand in for a layout that stores raw / 255
  // at the same voxel centres.
  bool holdsValues() const { return valid() && gradients_.valuesInAlpha; }
  // The GLSL part that defines LAYOUT_HAS_GRADIENT and sampleVolumeGradient()
  // from the texture; it goes before the layout's seam parts.
  static gpu::ShaderPart glsl();

 private:
  VoxelGradients gradients_;
  gpu::Texture texture_;
};

}  // namespace tessera::layout
