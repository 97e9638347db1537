// Several channels in the bricks layout (BricksLayout::createChannels,
// docs/channels.md): one brick holds every channel of its voxels, four a
// RGBA texel (Noguera & Jiménez 2012's packing, as ChannelLayout), so the
// page table, the level selection and the slots are the single-channel
// ones and one page lookup serves all channels (layout/channels_bricks.glsl).
// Also the channel uniforms ChannelLayout shares (ChannelUniforms.h).
//
// ES 2 has no 3D textures: the slots of a group of four channels are
// stacked in mosaics, and a page names a slot by mosaic (r) and place in its
// stack (b), 8 bits each, as the single-channel ES 2 atlas does: 255 slots a
// mosaic. A group takes K mosaics (1 + G K units with the page table), K as
// the profile's units allow after the ray caster's own, so a 3-channel store
// on a 16-unit WebGL 1 profile addresses 8 x 255 slots, not 255.
#include <algorithm>
#include <cmath>
#include <string>

#include "layout/ChannelUniforms.h"
#include "tessera/layout/BricksLayout.h"

namespace tessera::layout {

namespace {

// The ray caster's own units (transfer function, block grid) and a gradient
// texture: what the channel atlases leave free.
constexpr int kUnitsLeftForTechnique = 3;
constexpr int kMaxMosaicsPerGroup = 8;  // bricks.glsl's u_layoutAtlas0..7

int channelGroups(int channels) {
  return (channels + 3) / 4;
}

}  // namespace

int channelAtlasUnits(const gpu::DeviceLimits& limits, int channels) {
  if (limits.api == gpu::ApiLevel::Gles3) return 2;  // one 3D texture a group, 255^3 slots
  const int free = limits.textureUnits - 1 - kUnitsLeftForTechnique;
  return 1 + std::clamp(free / channelGroups(channels), 1, kMaxMosaicsPerGroup);
}

std::string channelSlotsNote(glm::ivec3 slots, bool es3, int channels) {
  if (es3) return "";
  const int groups = channelGroups(channels);
  return "; slots named by mosaic and place (8 bits each): " + std::to_string(slots.x) +
         (slots.x == 1 ? " mosaic" : " mosaics") + " of " + std::to_string(slots.z) +
         " slots per 4 channels, " + std::to_string(1 + groups * slots.x) + " texture units";
}

void BricksLayout::createChannelAtlases(gpu::MemoryLedger& ledger, gpu::TexelFormat format,
                                        glm::ivec3 slots, const MosaicLayout::Geometry& mosaic,
                                        int stored) {
  const int groups = channelGroups(channels_->size());
  const bool es3 = mosaic.tilesX == 0;
  atlasTexels_ = es3 ? slots * stored : glm::ivec3(stored, stored, slots.z * stored);
  for (int k = 0; k < (es3 ? 1 : slots.x); ++k) {
    for (int g = 0; g < groups; ++g) {
      std::string label = "brick atlas, channels " + std::to_string(4 * g) + ".." +
                          std::to_string(std::min(channels_->size(), 4 * g + 4) - 1);
      if (!es3 && slots.x > 1) label += ", mosaic " + std::to_string(k + 1);
      label += std::string(" (") + gpu::texelFormatName(format) + ")";
      atlases_.push_back(
          es3 ? gpu::Texture::create3D(ledger, label, format, atlasTexels_.x, atlasTexels_.y,
                                       atlasTexels_.z)
              : gpu::Texture::create2D(ledger, label, format, mosaic.width(), mosaic.height()));
    }
  }
}

int BricksLayout::channelMosaics() const {
  return mosaic_.tilesX == 0 ? 1 : slotGrid_.x;
}

// ES 3: two 3D samplers (the second the first again for four channels or
// fewer); ES 2: every mosaic of every group.
int BricksLayout::channelUnits() const {
  return mosaic_.tilesX == 0 ? 2 : static_cast<int>(atlases_.size());
}

gpu::ShaderPart BricksLayout::channelsGlsl() const {
  // Line 1 is a comment replaced by the compile-time counts (line numbers stay).
  gpu::ShaderPart part = gpu::embeddedShaderPart("layout/channels_bricks.glsl");
  part.text.replace(0, part.text.find('\n'),
                    "#define CHANNEL_GROUPS " + std::to_string(channelGroups(channels_->size())));
  return part;
}

void setChannelUniforms(const gpu::Program& program, const ChannelSet& set,
                        const std::vector<ValueMapping>& mappings, int textures) {
  program.set("u_layoutChannelTextures", static_cast<float>(textures));
  // normalised n = stored * scale + bias: raw = width * stored + min,
  // n = (raw - lo) / (hi - lo) (docs/channels.md).
  glm::vec4 scale[2]{}, bias[2]{}, on[2]{}, red[2]{}, green[2]{}, blue[2]{};
  for (int i = 0; i < set.size(); ++i) {
    const Channel& c = set[i];
    const ValueMapping& m = mappings[static_cast<std::size_t>(i)];
    const double ww = c.window.max - c.window.min;
    const int t = i / 4, k = i % 4;
    scale[t][k] = static_cast<float>(m.scale / ww);
    bias[t][k] = static_cast<float>((m.offset - c.window.min) / ww);
    on[t][k] = c.visible ? 1.0f : 0.0f;
    red[t][k] = static_cast<float>(c.color.r);
    green[t][k] = static_cast<float>(c.color.g);
    blue[t][k] = static_cast<float>(c.color.b);
  }
  for (int t = 0; t < 2; ++t) {
    const std::string s = std::to_string(t);
    program.set(("u_layoutChannelScale" + s).c_str(), scale[t]);
    program.set(("u_layoutChannelBias" + s).c_str(), bias[t]);
    program.set(("u_layoutChannelOn" + s).c_str(), on[t]);
    program.set(("u_layoutChannelRed" + s).c_str(), red[t]);
    program.set(("u_layoutChannelGreen" + s).c_str(), green[t]);
    program.set(("u_layoutChannelBlue" + s).c_str(), blue[t]);
  }
}

std::vector<std::shared_ptr<const lod::StoredBrick>> BricksLayout::channelBricks(
    const lod::BrickKey& key, bool readNow) {
  std::vector<std::shared_ptr<const lod::StoredBrick>> out;
  for (int c = 0; c < channels_->size(); ++c) {
    lod::BrickStreamer& s =
        c == 0 ? *streamer_ : *channelStreamers_[static_cast<std::size_t>(c - 1)];
    std::shared_ptr<const lod::StoredBrick> b = readNow ? s.readNow(key) : s.find(key);
    if (!b) return {};
    out.push_back(std::move(b));
  }
  return out;
}

namespace {

using Bricks = std::vector<std::shared_ptr<const lod::StoredBrick>>;

// Channel c's stored value of voxel i in [0, 1] of its packing range, 0 for
// the unused components of the last texel.
double storedFraction(const Bricks& bricks, const std::vector<glm::dvec2>& packing, int c,
                      std::size_t i) {
  if (c >= static_cast<int>(bricks.size())) return 0.0;
  const lod::StoredBrick& b = *bricks[static_cast<std::size_t>(c)];
  const glm::dvec2 p = packing[static_cast<std::size_t>(c)];
  return std::clamp((b.value(i) - p.x) / (p.y - p.x), 0.0, 1.0);
}

// Four channels from c0 of every voxel of the slot, as `format` takes them.
template <typename T>
std::vector<T> packed(const Bricks& bricks, const std::vector<glm::dvec2>& packing, int c0,
                      std::size_t voxels, double full) {
  std::vector<T> out(voxels * 4);
  for (std::size_t i = 0; i < voxels; ++i) {
    for (int k = 0; k < 4; ++k) {
      const double f = storedFraction(bricks, packing, c0 + k, i);
      out[4 * i + static_cast<std::size_t>(k)] =
          full > 0.0 ? static_cast<T>(std::lround(f * full)) : static_cast<T>(f);
    }
  }
  return out;
}

}  // namespace

void BricksLayout::uploadChannels(
    int slot, const std::vector<std::shared_ptr<const lod::StoredBrick>>& bricks) {
  const int n = grid_.stored();
  const glm::ivec3 s = slotOrigin(slot);
  keepFineRanges(slot, *bricks.front());  // channel 0's, for valueBlocks()
  const std::size_t voxels = static_cast<std::size_t>(n) * n * n;
  const auto atlasGroups = static_cast<std::size_t>(channelGroups(channels_->size()));
  for (std::size_t t = 0; t < atlasGroups; ++t) {
    const int c0 = 4 * static_cast<int>(t);
    std::vector<std::uint8_t> bytes8;
    std::vector<std::uint16_t> bytes16;
    std::vector<float> floats;
    const void* data = nullptr;
    std::size_t texelBytes = 0;
    if (channelFormat_ == gpu::TexelFormat::RGBA16) {
      bytes16 = packed<std::uint16_t>(bricks, channelPacking_, c0, voxels, 65535.0);
      data = bytes16.data();
      texelBytes = 8;
    } else if (channelFormat_ == gpu::TexelFormat::RGBA16F) {
      floats = packed<float>(bricks, channelPacking_, c0, voxels, 0.0);
      data = floats.data();
      texelBytes = 16;
    } else {
      bytes8 = packed<std::uint8_t>(bricks, channelPacking_, c0, voxels, 255.0);
      data = bytes8.data();
      texelBytes = 4;
    }
    if (mosaic_.tilesX == 0) {
      gpu::Texture& atlas = atlases_[t];
      atlas.updateRegion(s * n, glm::ivec3(n), data);
      continue;
    }
    // ES 2: mosaic s.x of the group, s.z the slot in its stack.
    gpu::Texture& atlas = atlases_[static_cast<std::size_t>(s.x) * atlasGroups + t];
    const std::size_t slice = static_cast<std::size_t>(n) * n * texelBytes;
    for (int k = 0; k < n; ++k) {
      const glm::ivec2 at = mosaic_.addressOf(0, 0, s.z * n + k);
      atlas.updateRegion({at, 0}, {n, n, 1}, static_cast<const std::uint8_t*>(data) + slice * k);
    }
  }
}

// A brick no visible channel shows: for each, its values windowed are
// where the TF is transparent (additive) or all 0 (max: nothing to take).
// It is not fetched; its cells show the coarser brick they fall back to.
bool BricksLayout::channelsTransparent(const lod::BrickKey& key, const TransferFunction& tf,
                                       bool exactOnly) const {
  for (int c = 0; c < channels_->size(); ++c) {
    const Channel& channel = (*channels_)[c];
    if (!channel.visible) continue;
    const lod::BrickStreamer& s =
        c == 0 ? *streamer_ : *channelStreamers_[static_cast<std::size_t>(c - 1)];
    const std::optional<lod::BrickRange> r = exactOnly ? s.range(key) : subtreeBound(key, s);
    if (!r) return false;
    const lod::StoredMapping& m = s.mapping();
    const double ww = channel.window.max - channel.window.min;
    const double a = std::clamp((m.raw(r->min) - channel.window.min) / ww, 0.0, 1.0);
    const double b = std::clamp((m.raw(r->max) - channel.window.min) / ww, 0.0, 1.0);
    if (channels_->mode == ChannelMode::Max) {
      if (b > 0.0) return false;
      continue;
    }
    if (tf.opacity(a) > 0.0 || tf.opacity(b) > 0.0) return false;
    for (const OpacityPoint& p : tf.opacities) {
      if (p.alpha > 0.0 && p.x > a && p.x < b) return false;
    }
  }
  return true;
}

void BricksLayout::bindChannels(const gpu::Program& program, int firstUnit) const {
  const int groups = channelGroups(channels_->size());
  if (mosaic_.tilesX == 0) {
    // Without a second atlas its sampler reads the first, and its channels are off.
    for (int t = 0; t < 2; ++t)
      atlases_[static_cast<std::size_t>(std::min(t, groups - 1))].bind(firstUnit + t);
    program.set("u_layoutAtlas", firstUnit);
    program.set("u_layoutChannels0", firstUnit);
    program.set("u_layoutChannels1", firstUnit + 1);
  } else {
    // Group 0's mosaics are bricks.glsl's u_layoutAtlas0..K-1 (channel 0 in .r).
    for (std::size_t i = 0; i < atlases_.size(); ++i) {
      const int unit = firstUnit + static_cast<int>(i);
      const int k = static_cast<int>(i) / groups, g = static_cast<int>(i) % groups;
      atlases_[i].bind(unit);
      const std::string name =
          (g == 0 ? "u_layoutAtlas" : "u_layoutChannels1_") + std::to_string(k);
      program.set(name.c_str(), unit);
    }
  }
  std::vector<ValueMapping> mappings;
  for (int c = 0; c < channels_->size(); ++c) {
    // raw = m.raw(lo + f (hi - lo)) for the component's f in [0, 1].
    const lod::StoredMapping& m =
        (c == 0 ? *streamer_ : *channelStreamers_[static_cast<std::size_t>(c - 1)]).mapping();
    const glm::dvec2 p = channelPacking_[static_cast<std::size_t>(c)];
    const double perStored = m.width / m.maxStored();
    mappings.push_back({(p.y - p.x) * perStored, m.min + p.x * perStored});
  }
  setChannelUniforms(program, *channels_, mappings, groups);
}

}  // namespace tessera::layout
