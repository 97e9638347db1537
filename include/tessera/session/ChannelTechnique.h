#pragma once
// The technique a channel frame is drawn with (docs/channels.md,
// "Techniques"): the one check Session::renderChannels and ChannelView share.
#include <string>

#include "tessera/render/TechniqueRegistry.h"

namespace tessera::session {

// The registry's entry for technique `name` when it draws channels
// (TechniqueEntry::drawsChannels); otherwise InputError "--technique X
// cannot draw channels: channel frames draw with raycast or ...".
const render::TechniqueEntry& channelTechnique(const std::string& name);

// Refuses a channel frame over the bricks layout (`layoutPlan`, its plan's
// reason) by a technique that does not draw channel bricks
// (TechniqueEntry::drawsChannelBricks): InputError "--technique X cannot draw
// channels from bricks (PLAN): use --technique raycast or ..., or --layout
// texture3d (ES 3) or mosaic (ES 2) where the channels fit in core".
void requireChannelBricks(const render::TechniqueEntry& entry, const std::string& layoutPlan);

}  // namespace tessera::session
