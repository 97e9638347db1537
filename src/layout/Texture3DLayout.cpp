#include "tessera/layout/Texture3DLayout.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "layout/Fit3DTexture.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/gpu/Draw.h"

namespace tessera::layout {

namespace {
std::string dimsText(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}
}  // namespace

LayoutPlan Texture3DLayout::planFor(const Volume& volume, const gpu::DeviceLimits& limits) {
  LayoutPlan plan;
  plan.layout = "texture3d";
  PlannedTexture t;
  t.label = "volume";
  t.size = volume.dims();
  t.is3D = true;
  std::uint64_t bpt = 1;
  if (volume.type() == ScalarType::U8) {
    t.format = "R8";
  } else {
    t.format = limits.norm16Textures ? "R16" : "R16F";
    bpt = 2;
  }
  t.bytes = volume.voxelCount() * bpt;
  plan.totalBytes = t.bytes;
  plan.textures.push_back(t);
  const std::string what = dimsText(volume.dims()) + " " +
                           std::string(scalarTypeName(volume.type())) + " in one " + t.format +
                           " 3D texture (" + formatBytes(t.bytes) + ")";
  plan.reason = refusalFor3DTexture(limits, volume.dims(), t.bytes, what,
                                    "no 3D textures on " + limits.profile, "the volume");
  plan.fits = plan.reason.empty();
  if (plan.fits) plan.reason = what;
  return plan;
}

std::unique_ptr<Texture3DLayout> Texture3DLayout::create(const Volume& volume,
                                                         const gpu::DeviceLimits& limits,
                                                         gpu::MemoryLedger& ledger) {
  std::unique_ptr<Texture3DLayout> l(new Texture3DLayout());
  l->voxels_ = &volume;
  l->plan_ = planFor(volume, limits);
  if (!l->plan_.fits) throw GpuError("texture3d layout: " + l->plan_.reason);
  l->dims_ = volume.dims();
  const glm::ivec3 d = volume.dims();
  if (volume.type() == ScalarType::U8) {
    l->texture_ = gpu::Texture::create3D(ledger, "volume (texture3d R8)", gpu::TexelFormat::R8, d.x,
                                         d.y, d.z, volume.bytes().data());
    l->mapping_ = {255.0, 0.0};
    return l;
  }
  // Normalise over the value range into 16 bits: raw = min + s * (max - min).
  const ValueRange r = volume.valueRange();
  const double width = r.max > r.min ? r.max - r.min : 1.0;
  l->mapping_ = {width, r.min};
  const std::size_t n = static_cast<std::size_t>(volume.voxelCount());
  HostBudget::global().check(n * 2, "texture3d upload staging");
  if (limits.norm16Textures) {
    std::vector<std::uint16_t> staging(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double v = volume.valueAtIndex(i);
      const double s = std::isfinite(v) ? std::clamp((v - r.min) / width, 0.0, 1.0) : 0.0;
      staging[i] = static_cast<std::uint16_t>(std::lround(s * 65535.0));
    }
    l->mapping_.scale = width;  // R16 normalised: s = stored/65535 exactly as above
    l->texture_ = gpu::Texture::create3D(ledger, "volume (texture3d R16)", gpu::TexelFormat::R16,
                                         d.x, d.y, d.z, staging.data());
  } else {
    std::vector<float> staging(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double v = volume.valueAtIndex(i);
      staging[i] =
          std::isfinite(v) ? static_cast<float>(std::clamp((v - r.min) / width, 0.0, 1.0)) : 0.0f;
    }
    l->texture_ = gpu::Texture::create3D(ledger, "volume (texture3d R16F)", gpu::TexelFormat::R16F,
                                         d.x, d.y, d.z, staging.data());
  }
  return l;
}

gpu::ShaderPart Texture3DLayout::glsl() const {
  return gpu::embeddedShaderPart("layout/texture3d.glsl");
}

int Texture3DLayout::bind(const gpu::Program& program, int firstUnit) const {
  texture_.bind(firstUnit);
  program.set("u_layoutVolume", firstUnit);
  return 1;
}

LayoutEntry Texture3DLayout::registration() {
  return {
      .name = "texture3d",
      .minApi = gpu::ApiLevel::Gles3,
      .needs3DTextures = true,
      .plan = [](const Volume& shape, const gpu::DeviceLimits& limits,
                 int) { return planFor(shape, limits); },
      .create = [](const Volume& volume, const gpu::DeviceLimits& limits, gpu::MemoryLedger& ledger,
                   int) -> std::unique_ptr<Layout> { return create(volume, limits, ledger); }};
}

}  // namespace tessera::layout
