#include "tessera/session/OverlayPanel.h"

#include <filesystem>

#include "tessera/core/Error.h"
#include "tessera/session/Session.h"

namespace tessera::session {

const std::vector<std::string>& overlayColourMaps() {
  static const std::vector<std::string> maps = {"hot", "grey", "mr-default", "ct-bone", "bench"};
  return maps;
}

OverlayOptions overlayOptionsOf(const OverlayControls& c) {
  const std::vector<std::string>& maps = overlayColourMaps();
  if (c.colourMap < 0 || c.colourMap >= static_cast<int>(maps.size())) {
    throw InputError("overlay colour map " + std::to_string(c.colourMap) + ": expected 0.." +
                     std::to_string(maps.size() - 1));
  }
  OverlayOptions o;
  o.labels = c.labels;
  if (c.labels) o.labelTable = c.table;
  o.tf = maps[static_cast<std::size_t>(c.colourMap)];
  o.opacity = c.alpha;
  if (c.window) o.window = ValueRange{c.lo, c.hi};
  return o;
}

void syncOverlayControls(OverlayControls& c, const Overlay& o) {
  c.labels = o.options.labels;
  if (o.options.labels) c.table = o.options.labelTable;
  const std::vector<std::string>& maps = overlayColourMaps();
  for (std::size_t i = 0; i < maps.size(); ++i) {
    if (maps[i] == o.options.tf) c.colourMap = static_cast<int>(i);
  }
  c.alpha = static_cast<float>(o.options.opacity);
  c.window = o.options.window.has_value();
  if (c.window) {
    c.lo = o.options.window->min;
    c.hi = o.options.window->max;
  }
}

void addOverlayFromPanel(Session& session, const std::string& path,
                         const OverlayControls& controls) {
  session.openOverlay(path, overlayOptionsOf(controls));
}

bool restyleOverlayFromPanel(Session& session, const OverlayControls& controls) {
  if (!session.overlay()) return false;
  session.restyleOpenOverlay(overlayOptionsOf(controls));
  return true;
}

void removeOverlayFromPanel(Session& session) {
  session.clearOverlay();
}

std::string overlayPanelLine(const Overlay& o) {
  const glm::ivec3 d = o.fused->volume->dims();
  return std::filesystem::path(o.name).filename().string() + " " + std::to_string(d.x) + "x" +
         std::to_string(d.y) + "x" + std::to_string(d.z) + ": " +
         (o.fused->labels ? std::to_string(o.labels.labels.size()) + " labels"
                          : "colour map " + o.options.tf);
}

}  // namespace tessera::session
