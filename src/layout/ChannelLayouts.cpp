#include "tessera/layout/ChannelLayouts.h"

#include "tessera/core/Error.h"
#include "tessera/layout/BricksLayout.h"
#include "tessera/layout/ChannelLayout.h"
#include "tessera/layout/LayoutRegistry.h"

namespace tessera::layout {

namespace {

const LayoutEntry* streamingEntry() {
  for (const LayoutEntry& e : LayoutRegistry::global().entries()) {
    if (e.streamsBricks) return &e;
  }
  return nullptr;
}

std::unique_ptr<Layout> channelBricks(const ChannelSet& set, const ChannelSources& sources,
                                      const gpu::DeviceLimits& limits, gpu::MemoryLedger& ledger) {
  return BricksLayout::createChannels(sources(), set, limits, ledger);
}

}  // namespace

LayoutPlan channelBricksPlan(const Volume& shape, const gpu::DeviceLimits& limits, int channels) {
  return BricksLayout::planFor(shape, limits, {.channels = channels});
}

std::string channelLayoutChoices(const ChannelSet& set, const gpu::DeviceLimits& limits) {
  std::string text = ChannelLayout::planFor(set, limits).layout;
  if (const LayoutEntry* e = streamingEntry()) text += " or " + e->name;
  return text;
}

std::unique_ptr<Layout> createChannelLayout(const std::string& wish, const ChannelSet& set,
                                            const ChannelSources& sources,
                                            const gpu::DeviceLimits& limits,
                                            gpu::MemoryLedger& ledger) {
  const LayoutPlan inCore = ChannelLayout::planFor(set, limits);
  if (wish.empty() || wish == "auto") {
    if (inCore.fits || !streamingEntry()) return ChannelLayout::create(set, limits, ledger);
    return channelBricks(set, sources, limits, ledger);
  }
  const LayoutEntry& entry = LayoutRegistry::global().find(wish);  // InputError if unknown
  if (entry.streamsBricks) return channelBricks(set, sources, limits, ledger);
  if (wish != inCore.layout) {
    throw InputError("--layout " + wish + " cannot draw channels on " + limits.profile +
                     ": channel frames draw in " + channelLayoutChoices(set, limits));
  }
  return ChannelLayout::create(set, limits, ledger);
}

}  // namespace tessera::layout
