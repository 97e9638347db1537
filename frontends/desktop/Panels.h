#pragma once
// The desktop viewer's panels that need no window: each draws its Dear
// ImGui widgets over the session-level model it edits (session::ChannelView,
// session::Session's overlay) and asks the window for the rest through a
// PanelHost. DesktopApp is the window's host; tests/desktop draws the same
// panels in an ImGui context without a platform backend and clicks them
// (PanelsChannelsTest.cpp, PanelsOverlayTest.cpp). They are built apart, as
// tessera_desktop_panels (cmake/DesktopViewer.cmake).
//
//   Panels.cpp          the control panel's window, a section's title
//   PanelsChannels.cpp  a store's channels: visibility, colour, window, mode
//   PanelsOverlay.cpp   a second volume over the first; a dropped file's offer
#include <string>

#include <imgui.h>

#include "tessera/core/Error.h"
#include "tessera/session/OverlayPanel.h"

namespace tessera::session {
class ChannelView;
class Session;
}  // namespace tessera::session

namespace tessera::desktop {

// The control panel: a window at the left edge, kPanelWidth wide and as high
// as the window, titled kPanelTitle; the panels are drawn inside it between
// beginControlPanel() and ImGui::End().
constexpr float kPanelWidth = 390.0f;
inline constexpr const char* kPanelTitle = "Tessera";
void beginControlPanel(float height);

// What a panel asks of the window it is drawn in.
class PanelHost {
 public:
  virtual ~PanelHost() = default;
  // An action's error for the panel's error line; "" clears it.
  virtual void setError(const std::string& message) = 0;
  // Opens `path` in place of the volume shown (as the file panel's Open).
  virtual void openFile(const std::string& path) = 0;
  // The overlay was added, restyled or removed: the slice views draw again.
  virtual void overlayChanged() = 0;
};

// Runs `action`; its Error goes to the host's error line (and true means it
// succeeded, the line cleared).
template <class Action>
bool reportErrors(PanelHost& host, Action&& action) {
  try {
    action();
    host.setError("");
    return true;
  } catch (const Error& e) {
    host.setError(e.what());
    return false;
  }
}

// A section's title, under a separator.
void section(const char* title);

// PanelsChannels.cpp: the channel list of `view` (open): per channel a
// visibility checkbox (ID path: i, "##visible"), a colour swatch ("##colour")
// and its window (i, "window", "##min" / "##max"); the mode combo ("mode")
// and "Show one channel". Each widget calls the view's setter.
void panelChannels(session::ChannelView& view, PanelHost& host);

// PanelsOverlay.cpp: what the overlay panel holds between frames.
struct OverlayUi {
  char path[512] = "";
  char table[512] = "";                      // ImGui's buffer of controls.table
  session::OverlayControls controls;         // session/OverlayPanel.h: what the actions take
  const session::Overlay* synced = nullptr;  // the overlay the controls show
  std::string dropped;                       // dropped while a volume is open: overlay or replace?
};

// The overlay panel: a path ("##overlaypath") and "Add overlay", the look's
// controls ("labels (atlas)", "colour map", "window", "alpha") and "Remove
// overlay", through session/OverlayPanel.h's actions on `session`.
void panelOverlay(session::Session& session, OverlayUi& ui, PanelHost& host);
// A file dropped on the window: opened (host.openFile) when no volume or a
// generated one is shown, else offered by drawDropOffer's popup.
void offerDrop(session::Session& session, OverlayUi& ui, PanelHost& host, const std::string& path);
// The offer's modal popup (kDropOfferTitle): "Add as overlay", "Replace" or
// "Cancel".
inline constexpr const char* kDropOfferTitle = "A second volume";
void drawDropOffer(session::Session& session, OverlayUi& ui, PanelHost& host);

}  // namespace tessera::desktop
