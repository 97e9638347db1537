#include "tessera/layout/GradientTexture.h"

#include "tessera/layout/LayoutRegistry.h"

#include <algorithm>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"

namespace tessera::layout {

GradientWish parseGradientWish(const std::string& text) {
  if (text == "auto") return GradientWish::Auto;
  if (text == "on-the-fly") return GradientWish::OnTheFly;
  if (text == "precomputed") return GradientWish::Precomputed;
  throw InputError("--gradient '" + text + "': expected auto, on-the-fly or precomputed");
}

GradientPlan planGradient(GradientWish wish, glm::ivec3 dims, const std::string& layoutName,
                          gpu::ApiLevel api, int max3DTextureSize, std::uint64_t budget,
                          std::uint64_t bytesInUse) {
  GradientPlan plan;
  plan.texture.label = "gradient";
  plan.texture.size = dims;
  plan.texture.is3D = true;
  plan.texture.format = "RGBA8";
  plan.texture.bytes = 4ull * static_cast<std::uint64_t>(dims.x) * dims.y * dims.z;
  const std::string what = "precomputed RGBA8 3D texture (" + formatBytes(plan.texture.bytes) +
                           "): 1 fetch per lit sample instead of 6";
  std::string refusal;
  if (wish == GradientWish::OnTheFly) {
    plan.reason = "on the fly (asked for): central differences, 6 fetches per lit sample";
    return plan;
  }
  const bool cartesian = LayoutRegistry::global().find(layoutName).holdsVoxelGrid;
  if (api != gpu::ApiLevel::Gles3 || max3DTextureSize == 0) {
    refusal = "no 3D textures in this context";
  } else if (!cartesian) {
    refusal = "the " + layoutName + " layout reconstructs its own field";
  } else if (std::max({dims.x, dims.y, dims.z}) > max3DTextureSize) {
    refusal = "the volume exceeds the 3D texture size " + std::to_string(max3DTextureSize);
  } else if (budget > 0 && bytesInUse + plan.texture.bytes > budget) {
    refusal = "it does not fit the budget (" + formatBytes(bytesInUse) + " of " +
              formatBytes(budget) + " in use)";
  }
  if (!refusal.empty()) {
    if (wish == GradientWish::Precomputed) {
      throw InputError("--gradient precomputed: " + refusal);
    }
    plan.reason = "on the fly (central differences, 6 fetches per lit sample): " + refusal;
    return plan;
  }
  plan.precomputed = true;
  plan.reason = what;
  return plan;
}

GradientTexture GradientTexture::create(gpu::MemoryLedger& ledger, const Volume& volume) {
  GradientTexture g;
  g.gradients_ = computeVoxelGradients(volume);
  const glm::ivec3 d = g.gradients_.dims;
  g.texture_ =
      gpu::Texture::create3D(ledger, "precomputed gradient (RGBA8)", gpu::TexelFormat::RGBA8, d.x,
                             d.y, d.z, g.gradients_.texels.data());
  return g;
}

int GradientTexture::bind(const gpu::Program& program, int unit, double rawPerStored) const {
  texture_.bind(unit);
  program.set("u_gradientTexture", unit);
  // code * step = raw per voxel; / rawPerStored = stored per voxel; * dims =
  // stored per texture-space unit, what sampleVolumeGradient() returns.
  program.set("u_gradientDecode",
              glm::vec3(gradients_.step * glm::dvec3(gradients_.dims) / rawPerStored));
  return 1;
}

gpu::ShaderPart GradientTexture::glsl() {
  return gpu::embeddedShaderPart("layout/gradient_texture.glsl");
}

}  // namespace tessera::layout
