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

}  // namespace tessera::session
