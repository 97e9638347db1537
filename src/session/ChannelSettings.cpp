#include "tessera/session/ChannelSettings.h"
#include "tessera/session/ChannelSettingsJson.h"

#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"

namespace tessera::session {

namespace {

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(item);
  return out;
}

std::string rangeText(ValueRange r) {
  char s[64];
  std::snprintf(s, sizeof s, "%g:%g", r.min, r.max);
  return s;
}

}  // namespace

std::vector<glm::dvec3> parseChannelColors(const std::string& text) {
  std::vector<glm::dvec3> out;
  for (const std::string& item : splitList(text)) {
    try {
      out.push_back(parseHexColor(item));
    } catch (const InputError& e) {
      throw InputError("--channel-colors '" + text + "': " + e.what());
    }
  }
  if (out.empty()) throw InputError("--channel-colors '" + text + "': no colour");
  return out;
}

std::vector<ValueRange> parseChannelWindows(const std::string& text) {
  std::vector<ValueRange> out;
  for (const std::string& item : splitList(text)) {
    const auto colon = item.find(':');
    double lo = 0.0, hi = 0.0;
    std::size_t usedLo = 0, usedHi = 0;
    bool ok = colon != std::string::npos;
    if (ok) {
      try {
        lo = std::stod(item.substr(0, colon), &usedLo);
        hi = std::stod(item.substr(colon + 1), &usedHi);
      } catch (const std::exception&) {
        ok = false;
      }
    }
    ok = ok && usedLo == colon && usedHi == item.size() - colon - 1;
    if (!ok) {
      throw InputError("--channel-windows '" + text + "': '" + item +
                       "' is not LO:HI (expected e.g. 100:2000,50:900)");
    }
    out.push_back({lo, hi});
  }
  if (out.empty()) throw InputError("--channel-windows '" + text + "': no window");
  return out;
}

void ChannelSettings::validate() const {
  if (static_cast<int>(indices.size()) > ChannelSet::kMaxChannels) {
    throw InputError("channels: " + std::to_string(indices.size()) + " chosen; at most " +
                     std::to_string(ChannelSet::kMaxChannels) + " are rendered together");
  }
  for (const glm::dvec3& c : colors) {
    for (int k = 0; k < 3; ++k) {
      if (!(c[k] >= 0.0 && c[k] <= 1.0))
        throw InputError("channel colour component " + std::to_string(c[k]) + ": expected 0..1");
    }
  }
  for (const ValueRange& w : windows) {
    if (!(w.max > w.min)) {
      throw InputError("channel window " + rangeText(w) + ": expected LO < HI");
    }
  }
  if (!indices.empty()) {
    const auto check = [&](std::size_t n, const char* what) {
      if (n != 0 && n != indices.size()) {
        throw InputError(std::string("channels: ") + std::to_string(n) + " " + what + " for " +
                         std::to_string(indices.size()) + " channels chosen");
      }
    };
    check(colors.size(), "colours");
    check(windows.size(), "windows");
    check(visible.size(), "visibility flags");
  }
}

void ChannelSettings::applyTo(ChannelSet& set, const std::string& spec) const {
  validate();
  const auto check = [&](std::size_t n, const char* what) {
    if (n != 0 && static_cast<int>(n) != set.size()) {
      throw InputError(spec + ": " + std::to_string(n) + " " + what + " for its " +
                       std::to_string(set.size()) + " channels");
    }
  };
  check(colors.size(), "channel colours");
  check(windows.size(), "channel windows");
  check(visible.size(), "channel visibility flags");
  for (int i = 0; i < set.size(); ++i) {
    const auto u = static_cast<std::size_t>(i);
    if (!colors.empty()) set[i].color = colors[u];
    if (!windows.empty()) set[i].window = windows[u];
    if (!visible.empty()) set[i].visible = visible[u];
  }
  set.mode = mode;
}

nlohmann::json channelSettingsToJson(const ChannelSettings& c) {
  nlohmann::json colorList = nlohmann::json::array();
  for (const glm::dvec3& rgb : c.colors) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "%02x%02x%02x", static_cast<unsigned>(rgb.r * 255.0 + 0.5),
                  static_cast<unsigned>(rgb.g * 255.0 + 0.5),
                  static_cast<unsigned>(rgb.b * 255.0 + 0.5));
    colorList.push_back(hex);
  }
  nlohmann::json windowList = nlohmann::json::array();
  for (const ValueRange& w : c.windows) windowList.push_back({w.min, w.max});
  nlohmann::json visibleList = nlohmann::json::array();
  for (bool v : c.visible) visibleList.push_back(v);
  return {{"indices", c.indices},
          {"colors", colorList},
          {"windows", windowList},
          {"visible", visibleList},
          {"mode", channelModeName(c.mode)}};
}

ChannelSettings channelSettingsFromJson(const nlohmann::json& j) {
  ChannelSettings c;
  c.enabled = true;
  try {
    c.indices = j.value("indices", std::vector<int>{});
    for (const auto& hex : j.value("colors", nlohmann::json::array())) {
      c.colors.push_back(parseHexColor(hex.get<std::string>()));
    }
    for (const auto& w : j.value("windows", nlohmann::json::array())) {
      if (!w.is_array() || w.size() != 2) throw InputError("channels.windows: expected [lo, hi]");
      c.windows.push_back({w[0].get<double>(), w[1].get<double>()});
    }
    for (const auto& v : j.value("visible", nlohmann::json::array())) {
      c.visible.push_back(v.get<bool>());
    }
    c.mode = parseChannelMode(j.value("mode", std::string("additive")));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(std::string("session state: channels: ") + e.what());
  }
  c.validate();
  return c;
}

}  // namespace tessera::session
