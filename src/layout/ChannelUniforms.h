#pragma once
// The u_layoutChannel* uniforms of layout/channels.glsl, which ChannelLayout
// and BricksLayout's channels share: per channel its window as n = stored *
// scale + bias (stored in [0,1] over the channel's mapping), its visibility
// and its colour, four channels per vec4 (docs/channels.md).
#include <string>
#include <vector>

#include "tessera/core/ChannelSet.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/Program.h"
#include "tessera/layout/Layout.h"

namespace tessera::layout {

// `mappings[i]`: channel i's raw value of stored 0..1 (raw = scale * stored
// + offset); `textures`: the RGBA textures (or atlases) holding them.
void setChannelUniforms(const gpu::Program& program, const ChannelSet& set,
                        const std::vector<ValueMapping>& mappings, int textures);

// Bricks of several channels on ES 2 (layout/ChannelBricks.cpp): a page
// names a slot by mosaic (r) and place in its stack (b, 8 bits: 255 slots a
// mosaic), so a group of four channels spreads its slots over K mosaics,
// one unit each. The units an atlas of `channels` may take per group, as
// BricksLayout's atlas shaping counts them: 1 + K (the page table and K).
int channelAtlasUnits(const gpu::DeviceLimits& limits, int channels);
// ", slots named by mosaic and place (K mosaics per 4 channels, 1 + G K
// units)" for the plan: how the slots are addressed.
std::string channelSlotsNote(glm::ivec3 slots, bool es3, int channels);

}  // namespace tessera::layout
