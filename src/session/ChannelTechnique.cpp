#include "tessera/session/ChannelTechnique.h"

#include "tessera/core/Error.h"

namespace tessera::session {

const render::TechniqueEntry& channelTechnique(const std::string& name) {
  const render::TechniqueRegistry& registry = render::TechniqueRegistry::global();
  const render::TechniqueEntry& entry = registry.find(name);
  if (entry.drawsChannels) return entry;
  std::string drawing;
  for (const render::TechniqueEntry& e : registry.entries()) {
    if (e.drawsChannels) drawing += (drawing.empty() ? "" : " or ") + e.name;
  }
  throw InputError("--technique " + name + " cannot draw channels: channel frames draw with " +
                   drawing);
}

}  // namespace tessera::session
