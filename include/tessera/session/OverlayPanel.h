#pragma once
// An overlay panel's logic (docs/fusion.md "In the viewers"): the controls
// it holds, the options they mean, and its three actions on a session. The
// desktop viewer's Overlay panel (frontends/desktop/PanelsOverlay.cpp) draws
// the controls and calls these; tests call the same functions with the same
// arguments (tests/session/OverlayPanelTest.cpp).
#include <string>
#include <vector>

#include "tessera/session/Fusion.h"

namespace tessera::session {

class Session;

struct OverlayControls {
  bool labels = false;
  std::string table;  // a label table file ("" : the default palette)
  int colourMap = 0;  // index into overlayColourMaps()
  float alpha = 0.5f;
  bool window = false;
  double lo = 0.0, hi = 1.0;
};

// The colour maps a panel offers, in its menu's order ("hot" first).
const std::vector<std::string>& overlayColourMaps();

// The options the controls mean; InputError for a colour map index outside
// the menu.
OverlayOptions overlayOptionsOf(const OverlayControls& controls);

// The controls showing an overlay opened elsewhere (--overlay, a state).
void syncOverlayControls(OverlayControls& controls, const Overlay& overlay);

// "Add overlay": the file at `path` over the session's volume, looked as
// the controls say (Session::openOverlay: its rules and messages).
void addOverlayFromPanel(Session& session, const std::string& path,
                         const OverlayControls& controls);
// A control changed: the open overlay restyled (its file not read again);
// false when none is open (nothing to do).
bool restyleOverlayFromPanel(Session& session, const OverlayControls& controls);
// "Remove overlay".
void removeOverlayFromPanel(Session& session);

// The panel's line about the open overlay: "aal.nii.gz 181x217x181: 116
// labels", or "hot.nii 91x109x91: colour map hot".
std::string overlayPanelLine(const Overlay& overlay);

}  // namespace tessera::session
