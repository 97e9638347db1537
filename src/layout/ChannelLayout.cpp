#include "tessera/layout/ChannelLayout.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "layout/ChannelUniforms.h"
#include "layout/Fit3DTexture.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/layout/MosaicLayout.h"

namespace tessera::layout {

namespace {

int textureCount(const ChannelSet& set) {
  return (set.size() + ChannelLayout::kChannelsPerTexture - 1) / ChannelLayout::kChannelsPerTexture;
}

bool usesMosaic(const gpu::DeviceLimits& limits) {
  return limits.api != gpu::ApiLevel::Gles3 || limits.max3DTextureSize == 0;
}

gpu::TexelFormat formatFor(const gpu::DeviceLimits& limits) {
  if (usesMosaic(limits)) return gpu::rgba8For(limits.api);
  return limits.norm16Textures ? gpu::TexelFormat::RGBA16 : gpu::TexelFormat::RGBA16F;
}

std::string dimsText(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

// Channel c's voxel i normalised over its value range (0 for a channel
// beyond the set: the unused components of the last texel).
double storedAt(const ChannelSet& set, int c, std::size_t i) {
  if (c >= set.size()) return 0.0;
  const Volume& v = *set[c].volume;
  const ValueRange r = v.valueRange();
  const double width = r.max > r.min ? r.max - r.min : 1.0;
  const double x = v.valueAtIndex(i);
  return std::isfinite(x) ? std::clamp((x - r.min) / width, 0.0, 1.0) : 0.0;
}

}  // namespace

LayoutPlan ChannelLayout::planFor(const ChannelSet& set, const gpu::DeviceLimits& limits) {
  LayoutPlan plan;
  const glm::ivec3 d = set.geometry().dims();
  const gpu::TexelFormat format = formatFor(limits);
  const bool mosaic = usesMosaic(limits);
  // The single-channel layout whose storage this extends (the gradient
  // planner and the reports look the name up in the LayoutRegistry).
  plan.layout = mosaic ? "mosaic" : "texture3d";
  const int n = textureCount(set);
  glm::ivec3 size = d;
  if (mosaic) {
    const MosaicLayout::Geometry g = MosaicLayout::geometryFor(d, limits.max2DTextureSize);
    size = {g.width(), g.height(), 1};
    if (g.tilesX == 0) {
      plan.reason = std::to_string(d.z) + " slices of " + std::to_string(d.x) + "x" +
                    std::to_string(d.y) + " do not fit a " +
                    std::to_string(limits.max2DTextureSize) + " mosaic on " + limits.profile;
      return plan;
    }
  }
  for (int t = 0; t < n; ++t) {
    PlannedTexture p;
    p.label = "channels " + std::to_string(t * kChannelsPerTexture) + ".." +
              std::to_string(std::min(set.size(), (t + 1) * kChannelsPerTexture) - 1);
    p.size = size;
    p.is3D = !mosaic;
    p.format = gpu::texelFormatName(format);
    p.bytes = static_cast<std::uint64_t>(size.x) * size.y * size.z * gpu::bytesPerTexel(format);
    plan.totalBytes += p.bytes;
    plan.textures.push_back(p);
  }
  const std::string what = std::to_string(set.size()) + " channels of " + dimsText(d) + " in " +
                           std::to_string(n) + " " + gpu::texelFormatName(format) +
                           (mosaic ? " mosaic" : " 3D texture") + (n > 1 ? "s" : "") + " (" +
                           formatBytes(plan.totalBytes) + ")";
  if (mosaic) {
    if (limits.textureBudget != 0 && plan.totalBytes > limits.textureBudget) {
      plan.reason = what + " exceeds the texture budget " + formatBytes(limits.textureBudget) +
                    " of " + limits.profile;
    }
  } else {
    plan.reason =
        refusalFor3DTexture(limits, d, plan.totalBytes, what, "no 3D textures", "the channels");
  }
  plan.fits = plan.reason.empty();
  if (plan.fits) plan.reason = what;
  return plan;
}

std::unique_ptr<ChannelLayout> ChannelLayout::create(const ChannelSet& set,
                                                     const gpu::DeviceLimits& limits,
                                                     gpu::MemoryLedger& ledger) {
  std::unique_ptr<ChannelLayout> l(new ChannelLayout());
  l->plan_ = planFor(set, limits);
  if (!l->plan_.fits) throw GpuError("channel layout: " + l->plan_.reason);
  l->set_ = &set;
  l->voxels_ = &set.geometry();
  l->dims_ = set.geometry().dims();
  l->mosaic_ = usesMosaic(limits);
  for (const Channel& c : set.channels()) {
    const ValueRange r = c.volume->valueRange();
    l->mappings_.push_back({r.max > r.min ? r.max - r.min : 1.0, r.min});
  }
  l->upload(limits, ledger);
  return l;
}

void ChannelLayout::upload(const gpu::DeviceLimits& limits, gpu::MemoryLedger& ledger) {
  const gpu::TexelFormat format = formatFor(limits);
  const glm::ivec3 d = dims_;
  const std::size_t voxels = static_cast<std::size_t>(set_->geometry().voxelCount());
  MosaicLayout::Geometry g;
  if (mosaic_) {
    g = MosaicLayout::geometryFor(d, limits.max2DTextureSize);
    tilesX_ = g.tilesX;
    mosaicSize_ = {g.width(), g.height()};
  }
  const std::size_t texels =
      mosaic_ ? static_cast<std::size_t>(g.width()) * static_cast<std::size_t>(g.height()) : voxels;
  HostBudget::global().check(texels * gpu::uploadBytesPerTexel(format), "channel upload staging");
  for (int t = 0; t < textureCount(*set_); ++t) {
    const std::string label = "channels " + std::to_string(t) + " (" + plan_.layout + ")";
    // Where voxel i's texel lies in the upload: itself, or its mosaic tile.
    const auto texelOf = [&](std::size_t i) -> std::size_t {
      if (!mosaic_) return i;
      const int x = static_cast<int>(i % static_cast<std::size_t>(d.x));
      const int y = static_cast<int>((i / static_cast<std::size_t>(d.x)) % d.y);
      const int z = static_cast<int>(i / (static_cast<std::size_t>(d.x) * d.y));
      const glm::ivec2 a = g.addressOf(x, y, z);
      return static_cast<std::size_t>(a.y) * g.width() + a.x;
    };
    const int c0 = t * kChannelsPerTexture;
    if (format == gpu::TexelFormat::RGBA16F) {
      std::vector<float> staging(texels * 4, 0.0f);
      for (std::size_t i = 0; i < voxels; ++i) {
        for (int k = 0; k < 4; ++k)
          staging[texelOf(i) * 4 + k] = static_cast<float>(storedAt(*set_, c0 + k, i));
      }
      textures_.push_back(
          gpu::Texture::create3D(ledger, label, format, d.x, d.y, d.z, staging.data()));
    } else if (format == gpu::TexelFormat::RGBA16) {
      std::vector<std::uint16_t> staging(texels * 4, 0);
      for (std::size_t i = 0; i < voxels; ++i) {
        for (int k = 0; k < 4; ++k) {
          staging[i * 4 + k] =
              static_cast<std::uint16_t>(std::lround(storedAt(*set_, c0 + k, i) * 65535.0));
        }
      }
      textures_.push_back(
          gpu::Texture::create3D(ledger, label, format, d.x, d.y, d.z, staging.data()));
    } else {
      std::vector<std::uint8_t> staging(texels * 4, 0);
      for (std::size_t i = 0; i < voxels; ++i) {
        for (int k = 0; k < 4; ++k) {
          staging[texelOf(i) * 4 + k] =
              static_cast<std::uint8_t>(std::lround(storedAt(*set_, c0 + k, i) * 255.0));
        }
      }
      if (mosaic_) {
        textures_.push_back(
            gpu::Texture::create2D(ledger, label, format, g.width(), g.height(), staging.data()));
      } else {
        textures_.push_back(
            gpu::Texture::create3D(ledger, label, format, d.x, d.y, d.z, staging.data()));
      }
    }
  }
}

std::uint64_t ChannelLayout::textureBytes() const {
  std::uint64_t b = 0;
  for (const gpu::Texture& t : textures_) b += t.bytes();
  return b;
}

gpu::ShaderPart ChannelLayout::glsl() const {
  return gpu::embeddedShaderPart(mosaic_ ? "layout/channels_mosaic.glsl"
                                         : "layout/channels_texture3d.glsl");
}

std::vector<gpu::ShaderPart> ChannelLayout::glslParts() const {
  return {glsl(), gpu::embeddedShaderPart("layout/channels.glsl")};
}

int ChannelLayout::bind(const gpu::Program& program, int firstUnit) const {
  // Without a second texture its sampler reads the first, and its
  // channels are off.
  for (int t = 0; t < 2; ++t) {
    textures_[std::min<std::size_t>(static_cast<std::size_t>(t), textures_.size() - 1)].bind(
        firstUnit + t);
  }
  program.set("u_layoutChannels0", firstUnit);
  program.set("u_layoutChannels1", firstUnit + 1);
  setChannelUniforms(program, *set_, mappings_, static_cast<int>(textures_.size()));
  if (mosaic_) {
    program.set("u_layoutDims", glm::vec3(dims_));
    program.set("u_layoutTilesX", static_cast<float>(tilesX_));
    program.set("u_layoutInvSize", 1.0f / glm::vec2(mosaicSize_));
  }
  return 2;
}

}  // namespace tessera::layout
