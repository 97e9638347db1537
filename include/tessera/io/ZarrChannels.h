#pragma once
// Several channels of an OME-Zarr image read together (core/ChannelSet.h),
// with the store's omero rendering metadata as their defaults: colour,
// window (start/end) and visibility (active).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tessera/core/ChannelSet.h"
#include "tessera/io/ZarrStorage.h"

namespace tessera {

class ZarrStore;

// Channels `indices` of time point `time` (empty: every channel of the c
// axis), each read at the finest level that fits the host budget (all at
// the same level). InputError naming the store and the channel for an
// index outside the c axis, a repeated index, or more than
// ChannelSet::kMaxChannels.
ChannelSet readZarrChannels(const std::string& spec, const std::vector<int>& indices = {},
                            int time = 0);

// The same over a storage the caller opened (the page's fetch() storage),
// `name` naming the store in the messages.
ChannelSet readZarrChannels(std::shared_ptr<const ZarrStorage> storage, const std::string& name,
                            const std::vector<int>& indices = {}, int time = 0);
// Whether the storage holds every read readZarrChannels(storage, ...)
// makes (ZarrStore::holdsReads, `holds` asked about each): what an
// asynchronous storage must hold before the read (the same checks).
bool holdsZarrChannelReads(std::shared_ptr<const ZarrStorage> storage, const std::string& name,
                           const std::vector<int>& indices, int time,
                           const std::function<bool(const ZarrStoredRead&)>& holds);

// What readZarrChannels checks and makes, for a caller that reads the
// voxels itself (a store's channels streamed over bricks): the channels
// `indices` chooses of `store`'s c axis (empty: every one; InputError as
// readZarrChannels), and channel c as its omero metadata describes it, its
// voxels (or only its shape) `volume`.
std::vector<int> zarrChannelIndices(const ZarrStore& store, const std::string& spec,
                                    const std::vector<int>& indices);
Channel zarrChannel(const ZarrStore& store, int c, Volume volume);

// "0,2,3" as channel indices; InputError naming the text otherwise.
std::vector<int> parseChannelList(const std::string& text);

}  // namespace tessera
