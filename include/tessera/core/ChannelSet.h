#pragma once
// Several channels of one image seen together (microscopy: 2-6 fluorophores
// on one grid): per channel a single-channel Volume, a colour, a window in
// stored units and a visibility flag, and how the channels combine
// (docs/channels.md gives the one definition the GPU and the reference
// follow).
#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/core/RenderSettings.h"
#include "tessera/core/Volume.h"

namespace tessera {

enum class ChannelMode {
  Additive,  // emission-absorption with the channels' colours summed per sample
  Max,       // per channel maximum intensity projection, colours summed
};

// "additive" | "max"; InputError naming the accepted words otherwise.
ChannelMode parseChannelMode(const std::string& text);
const char* channelModeName(ChannelMode mode);
// The ray caster's mode for a channel mode: composite for additive, MIP for
// max (the march is the same; render/channels.glsl combines the channels).
inline RenderMode renderModeFor(ChannelMode mode) {
  return mode == ChannelMode::Max ? RenderMode::Mip : RenderMode::Composite;
}

struct Channel {
  std::shared_ptr<const Volume> volume;
  std::string label;
  glm::dvec3 color{1.0};    // linear RGB in [0,1]
  ValueRange window{0, 1};  // raw values mapped to 0 and 1
  bool visible = true;
};

class ChannelSet {
 public:
  static constexpr int kMaxChannels = 6;

  // Appends a channel; InputError when there are already kMaxChannels, when
  // its dims or geometry differ from the first channel's, or its window is
  // empty. `what` names the source in the messages.
  void add(Channel channel, const std::string& what = "channel");
  int size() const { return static_cast<int>(channels_.size()); }
  bool empty() const { return channels_.empty(); }
  const Channel& operator[](int i) const { return channels_.at(static_cast<std::size_t>(i)); }
  Channel& operator[](int i) { return channels_.at(static_cast<std::size_t>(i)); }
  const std::vector<Channel>& channels() const { return channels_; }
  // The first channel's volume: dims, spacing, extent and frame of them all.
  const Volume& geometry() const;

  ChannelMode mode = ChannelMode::Additive;

 private:
  std::vector<Channel> channels_;
};

// "ff8000" (optionally "#ff8000") as 0..1 RGB; InputError otherwise.
glm::dvec3 parseHexColor(const std::string& text);

}  // namespace tessera
