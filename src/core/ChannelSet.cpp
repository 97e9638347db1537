#include "tessera/core/ChannelSet.h"

#include <cctype>
#include <cmath>

#include "tessera/core/Error.h"

namespace tessera {

ChannelMode parseChannelMode(const std::string& text) {
  if (text == "additive") return ChannelMode::Additive;
  if (text == "max") return ChannelMode::Max;
  throw InputError("channel mode '" + text + "': expected additive or max");
}

const char* channelModeName(ChannelMode mode) {
  return mode == ChannelMode::Max ? "max" : "additive";
}

namespace {
bool sameGeometry(const Volume& a, const Volume& b) {
  const auto near = [](glm::dvec3 x, glm::dvec3 y) {
    return std::abs(x.x - y.x) + std::abs(x.y - y.y) + std::abs(x.z - y.z) <= 1e-9;
  };
  return a.dims() == b.dims() && near(a.spacing(), b.spacing()) && near(a.origin(), b.origin()) &&
         a.direction() == b.direction();
}
}  // namespace

void ChannelSet::add(Channel channel, const std::string& what) {
  if (!channel.volume) throw InputError(what + ": no voxels");
  if (size() >= kMaxChannels) {
    throw InputError(what + ": at most " + std::to_string(kMaxChannels) +
                     " channels are rendered together");
  }
  if (!channels_.empty() && !sameGeometry(geometry(), *channel.volume)) {
    throw InputError(what + ": its grid differs from channel " + channels_.front().label +
                     "'s (dims, spacing, origin and direction must match)");
  }
  if (!(channel.window.max > channel.window.min)) {
    throw InputError(what + ": window " + std::to_string(channel.window.min) + ":" +
                     std::to_string(channel.window.max) + " is empty (expected lo < hi)");
  }
  channels_.push_back(std::move(channel));
}

const Volume& ChannelSet::geometry() const {
  if (channels_.empty()) throw Error("channel set: no channels");
  return *channels_.front().volume;
}

glm::dvec3 parseHexColor(const std::string& text) {
  const std::string hex = !text.empty() && text[0] == '#' ? text.substr(1) : text;
  bool ok = hex.size() == 6;
  for (char c : hex) ok = ok && std::isxdigit(static_cast<unsigned char>(c));
  if (!ok) throw InputError("colour '" + text + "': expected six hex digits RRGGBB");
  const unsigned long v = std::stoul(hex, nullptr, 16);
  return glm::dvec3((v >> 16) & 0xff, (v >> 8) & 0xff, v & 0xff) / 255.0;
}

}  // namespace tessera
