#pragma once
// Several channels of one grid in RGBA textures, four channels per texel
// (Noguera & Jiménez 2012 pack four slices per RGBA texel; here the four
// components hold four channels of the same voxel), so that one fetch reads
// four channels and up to six need two textures (docs/channels.md):
//  - ES 3: 3D textures, RGBA16 with EXT_texture_norm16 (16 bits per channel,
//    as texture3d keeps u16 data), else RGBA16F;
//  - ES 2 (no 3D textures): the z-slices tiled in 2D RGBA8 mosaics
//    (MosaicLayout's grid), 8 bits per channel as the ES 2 mosaic keeps.
// Each channel is normalised over its own value range; the window, colour
// and visibility travel as uniforms, so changing them re-uploads nothing.
// Its GLSL defines CHANNELS, sampleChannels(p, n0, n1) (the normalised
// values of channels 0-3 and 4-5) and the u_layoutChannel* uniforms that
// render/channels.glsl combines.
#include <memory>

#include "tessera/core/ChannelSet.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/MemoryLedger.h"
#include "tessera/layout/Layout.h"

namespace tessera::layout {

class ChannelLayout final : public Layout {
 public:
  // Channels per texture and textures for kMaxChannels.
  static constexpr int kChannelsPerTexture = 4;

  // What create() would allocate on `limits`; plan.fits and plan.reason.
  static LayoutPlan planFor(const ChannelSet& channels, const gpu::DeviceLimits& limits);
  // Uploads the channels (which must outlive the layout). GpuError when the
  // plan does not fit.
  static std::unique_ptr<ChannelLayout> create(const ChannelSet& channels,
                                               const gpu::DeviceLimits& limits,
                                               gpu::MemoryLedger& ledger);

  // "texture3d" or "mosaic": the storage it extends to four channels a texel.
  std::string name() const override { return plan_.layout; }
  const LayoutPlan& plan() const override { return plan_; }
  gpu::ShaderPart glsl() const override;
  // glsl() (the storage's texel fetch) and layout/channels.glsl.
  std::vector<gpu::ShaderPart> glslParts() const override;
  int bind(const gpu::Program& program, int firstUnit) const override;
  // Channel 0's mapping (sampleVolume() reads channel 0).
  ValueMapping rawFromStored() const override { return mappings_.front(); }
  int textureUnits() const override { return 2; }
  glm::ivec3 volumeDims() const override { return dims_; }
  std::uint64_t textureBytes() const override;
  // Windows, colours, visibility and mode are read from the set at bind().
  const ChannelSet& channels() const { return *set_; }
  bool drawsChannels() const override { return true; }

 private:
  ChannelLayout() = default;
  void upload(const gpu::DeviceLimits& limits, gpu::MemoryLedger& ledger);
  LayoutPlan plan_;
  const ChannelSet* set_ = nullptr;
  std::vector<gpu::Texture> textures_;
  std::vector<ValueMapping> mappings_;
  glm::ivec3 dims_{0};
  bool mosaic_ = false;
  int tilesX_ = 0;
  glm::ivec2 mosaicSize_{0};
};

}  // namespace tessera::layout
