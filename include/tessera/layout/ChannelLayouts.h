#pragma once
// The layout a channel frame draws in (docs/channels.md "Layouts"), for the
// session's layout wish:
//  - the layout ChannelLayout extends on this device (texture3d on ES 3,
//    mosaic on ES 2): every channel in core, four a texel;
//  - a layout that streams bricks (LayoutEntry::streamsBricks):
//    BricksLayout::createChannels over one source per channel;
//  - "auto": ChannelLayout when its plan fits the device, else the bricks.
// Any other layout cannot draw channels: InputError saying which can.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tessera/core/ChannelSet.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/MemoryLedger.h"
#include "tessera/layout/Layout.h"
#include "tessera/lod/MultiresSource.h"

namespace tessera::layout {

// One source per channel of the set, in its order (called only for bricks).
using ChannelSources = std::function<std::vector<std::shared_ptr<const lod::MultiresSource>>()>;

std::unique_ptr<Layout> createChannelLayout(const std::string& wish, const ChannelSet& set,
                                            const ChannelSources& sources,
                                            const gpu::DeviceLimits& limits,
                                            gpu::MemoryLedger& ledger);

// What BricksLayout::createChannels would allocate for `channels` channels
// of `shape`'s grid on `limits` (`tessera plan --channels N`): the atlas, and
// on ES 2 how its slots are named (mosaics per group of four channels).
LayoutPlan channelBricksPlan(const Volume& shape, const gpu::DeviceLimits& limits, int channels);

// "texture3d or bricks": the layouts that draw channels on `limits`.
std::string channelLayoutChoices(const ChannelSet& set, const gpu::DeviceLimits& limits);

}  // namespace tessera::layout
