#pragma once
// Several channels of an OME-Zarr image read together (core/ChannelSet.h),
// with the store's omero rendering metadata as their defaults: colour,
// window (start/end) and visibility (active).
#include <string>
#include <vector>

#include "tessera/core/ChannelSet.h"

namespace tessera {

// Channels `indices` of time point `time` (empty: every channel of the c
// axis), each read at the finest level that fits the host budget (all at
// the same level). InputError naming the store and the channel for an
// index outside the c axis, a repeated index, or more than
// ChannelSet::kMaxChannels.
ChannelSet readZarrChannels(const std::string& spec, const std::vector<int>& indices = {},
                            int time = 0);

// "0,2,3" as channel indices; InputError naming the text otherwise.
std::vector<int> parseChannelList(const std::string& text);

}  // namespace tessera
