#pragma once
// ChannelSettings in the session state: the "channels" key, written only
// when channels are enabled, e.g.
//   {"indices": [0, 2], "colors": ["ff0000", "00ff00"],
//    "windows": [[100, 2000], [50, 900]], "visible": [true, true], "mode": "additive"}
#include <nlohmann/json_fwd.hpp>

#include "tessera/session/ChannelSettings.h"

namespace tessera::session {

nlohmann::json channelSettingsToJson(const ChannelSettings& c);
// Validated; InputError naming "channels" for a wrong kind or value.
ChannelSettings channelSettingsFromJson(const nlohmann::json& j);

}  // namespace tessera::session
