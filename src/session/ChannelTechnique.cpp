#include "tessera/session/ChannelTechnique.h"

#include "tessera/core/Error.h"

namespace tessera::session {

namespace {

// "raycast or slice3d or slice2d": the registry's techniques for which `draws` holds.
std::string techniquesThat(bool render::TechniqueEntry::*draws) {
  std::string names;
  for (const render::TechniqueEntry& e : render::TechniqueRegistry::global().entries()) {
    if (e.*draws) names += (names.empty() ? "" : " or ") + e.name;
  }
  return names;
}

}  // namespace

const render::TechniqueEntry& channelTechnique(const std::string& name) {
  const render::TechniqueRegistry& registry = render::TechniqueRegistry::global();
  const render::TechniqueEntry& entry = registry.find(name);
  if (entry.drawsChannels) return entry;
  throw InputError("--technique " + name + " cannot draw channels: channel frames draw with " +
                   techniquesThat(&render::TechniqueEntry::drawsChannels));
}

void requireChannelBricks(const render::TechniqueEntry& entry, const std::string& layoutPlan) {
  if (entry.drawsChannelBricks) return;
  throw InputError("--technique " + entry.name + " cannot draw channels from bricks (" +
                   layoutPlan + "): use --technique " +
                   techniquesThat(&render::TechniqueEntry::drawsChannelBricks) +
                   ", or --layout texture3d (ES 3) or mosaic (ES 2) where the channels fit in "
                   "core");
}

}  // namespace tessera::session
