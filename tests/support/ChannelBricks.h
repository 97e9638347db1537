#pragma once
// What the channel-bricks tests share (tests/render/ChannelBricksTest.cpp,
// ChannelSliceTest.cpp): the channels' in-core pyramids as the bricks
// layout's sources, and the levels a refined frame shows, read from them,
// as the reference of that frame reads them (Session::renderChannels).
#include <memory>
#include <vector>

#include "tessera/core/ChannelSet.h"
#include "tessera/layout/StreamingLayout.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/lod/ReadLevel.h"
#include "tessera/reference/ChannelReference.h"

namespace tessera::test {

// One in-core pyramid per channel (BricksLayout::createChannels' sources).
inline std::vector<std::shared_ptr<const lod::MultiresSource>> channelPyramids(
    const ChannelSet& set) {
  std::vector<std::shared_ptr<const lod::MultiresSource>> out;
  for (const Channel& c : set.channels())
    out.push_back(std::make_shared<lod::InCoreMultiresSource>(c.volume));
  return out;
}

// The levels `layout`'s page table shows, each read from the channels'
// pyramids: what the reference of its frame reads.
inline ChannelLevels channelLevelsShown(const ChannelSet& set,
                                        const layout::StreamingLayout& layout) {
  const lod::BrickGrid& grid = layout.grid();
  ChannelLevels out;
  out.cells = {grid.dims(0), grid.brickSize(), grid.bricks(0), layout.cellLevels()};
  for (int l = 0; l < grid.levelCount(); ++l) out.scales.push_back(grid.scale(l));
  for (const Channel& c : set.channels()) {
    const lod::InCoreMultiresSource pyramid(c.volume);
    out.volumes.emplace_back();
    for (int l = 0; l < grid.levelCount(); ++l)
      out.volumes.back().push_back(std::make_shared<const Volume>(lod::readLevel(pyramid, l)));
  }
  return out;
}

}  // namespace tessera::test
