#include "tessera/io/ZarrChannels.h"

#include <algorithm>
#include <memory>
#include <sstream>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/io/ZarrStore.h"

namespace tessera {

std::vector<int> parseChannelList(const std::string& text) {
  std::vector<int> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    std::size_t used = 0;
    int v = -1;
    try {
      v = std::stoi(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || v < 0) {
      throw InputError("--channels '" + text + "': '" + item +
                       "' is not a channel index (expected e.g. 0,2)");
    }
    out.push_back(v);
  }
  if (out.empty()) throw InputError("--channels '" + text + "': no channel index");
  return out;
}

// The channels chosen (every one when `indices` is empty), checked.
std::vector<int> zarrChannelIndices(const ZarrStore& store, const std::string& spec,
                                    const std::vector<int>& indices) {
  const int count = store.channelCount();
  std::vector<int> chosen = indices;
  if (chosen.empty()) {
    for (int c = 0; c < count; ++c) chosen.push_back(c);
  }
  if (static_cast<int>(chosen.size()) > ChannelSet::kMaxChannels) {
    throw InputError(spec + ": " + std::to_string(chosen.size()) + " channels chosen; at most " +
                     std::to_string(ChannelSet::kMaxChannels) +
                     " are rendered together (choose some with --channels)");
  }
  for (std::size_t i = 0; i < chosen.size(); ++i) {
    if (chosen[i] < 0 || chosen[i] >= count) {
      throw InputError(spec + ": channel " + std::to_string(chosen[i]) +
                       " is outside the store's " + std::to_string(count) + " channels (0.." +
                       std::to_string(count - 1) + ")");
    }
    if (std::find(chosen.begin(), chosen.begin() + static_cast<std::ptrdiff_t>(i), chosen[i]) !=
        chosen.begin() + static_cast<std::ptrdiff_t>(i)) {
      throw InputError(spec + ": channel " + std::to_string(chosen[i]) + " is chosen twice");
    }
  }
  return chosen;
}

Channel zarrChannel(const ZarrStore& store, int c, Volume volume) {
  const std::vector<ZarrChannel>& omero = store.channels();
  Channel ch;
  ch.label = "channel " + std::to_string(c);
  ch.window = volume.window();  // the reader applies omero's window for the channel
  if (static_cast<std::size_t>(c) < omero.size()) {
    const ZarrChannel& o = omero[static_cast<std::size_t>(c)];
    if (!o.label.empty()) ch.label = o.label;
    ch.color = glm::dvec3(o.color);
    ch.visible = o.active;
    if (o.hasWindow && o.window.max > o.window.min) ch.window = o.window;
  }
  if (!(ch.window.max > ch.window.min)) ch.window = {ch.window.min, ch.window.min + 1.0};
  ch.volume = std::make_shared<Volume>(std::move(volume));
  return ch;
}

ChannelSet readZarrChannels(const std::string& spec, const std::vector<int>& indices, int time) {
  return readZarrChannels(openZarrStorage(spec), spec, indices, time);
}

ChannelSet readZarrChannels(std::shared_ptr<const ZarrStorage> storage, const std::string& name,
                            const std::vector<int>& indices, int time) {
  const ZarrStore first(storage, ZarrSelection{.time = time, .channel = 0});
  ChannelSet set;
  for (int c : zarrChannelIndices(first, name, indices)) {
    const ZarrStore store(storage, ZarrSelection{.time = time, .channel = c});
    Volume volume = store.readLevel(store.finestLevelInHostBudget(name));
    set.add(zarrChannel(store, c, std::move(volume)), name + " channel " + std::to_string(c));
  }
  return set;
}

bool holdsZarrChannelReads(std::shared_ptr<const ZarrStorage> storage, const std::string& name,
                           const std::vector<int>& indices, int time,
                           const std::function<bool(const ZarrStoredRead&)>& holds) {
  const ZarrStore first(storage, ZarrSelection{.time = time, .channel = 0});
  bool all = true;
  for (int c : zarrChannelIndices(first, name, indices)) {
    const ZarrStore store(storage, ZarrSelection{.time = time, .channel = c});
    const int l = store.finestLevelInHostBudget(name);
    all = store.holdsReads(l, glm::ivec3(0), store.level(l).dims, holds) && all;
  }
  return all;
}

}  // namespace tessera
