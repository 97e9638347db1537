#pragma once
// The desktop viewer's panels, drawn without a window: each draws its Dear
// ImGui widgets over the session-level model it edits (session::Session,
// its view, exploration, playback, overlay and session::ChannelView), keeps
// what it holds between frames in a small struct of its own (FileUi,
// TimeUi, StyleUi, ExploreUi, OverlayUi) and asks the window for the rest
// through a PanelHost. DesktopApp is the window's host; tests/desktop draws
// the same panels in an ImGui context without a platform backend and clicks
// them. They are built apart, as tessera_desktop_panels
// (cmake/DesktopViewer.cmake).
//
//   Panels.cpp          the control panel's window, a section's title
//   PanelsFile.cpp      open a file, recent volumes, save / load the state, the error line
//   PanelsTime.cpp      a time series: the time point's slider, play / pause, the rate
//   PanelsChannels.cpp  a store's channels: visibility, colour, window, mode
//   PanelsExplore.cpp   overview / region / grid at native resolution, the zoom stages
//   PanelsOverlay.cpp   a second volume over the first; a dropped file's offer
//   PanelsDrop.cpp      the paths the window's drop callback hands over
//   PanelsStyle.cpp     TF editor, window/level, rendering, shading, clipping, labels
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <imgui.h>

#include "tessera/core/Error.h"
#include "tessera/lod/GridNavigator.h"
#include "tessera/session/Exploration.h"
#include "tessera/session/OverlayPanel.h"
#include "tessera/session/Session.h"
#include "tessera/viewer/RecentFiles.h"

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
  // The error line as it stands (the file panel draws it).
  virtual const std::string& errorLine() const = 0;
  // Opens `path` in place of the volume shown (as the file panel's Open).
  virtual void openFile(const std::string& path) = 0;
  // The overlay was added, restyled or removed: the slice views draw again.
  virtual void overlayChanged() = 0;
  // The 3D view shows another volume, time point, region or grid block: the
  // slice views and the view's lines are made again.
  virtual void viewChanged() = 0;
  // A saved state was restored (Session::loadState): what the window shows
  // of it follows (the crop box's handles, the slice views, the lines).
  virtual void stateLoaded() = 0;
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

// Runs `action` once per frame: its Error goes to the host's error line,
// which is left as it is when it succeeds (true).
template <class Action>
bool reportFailure(PanelHost& host, Action&& action) {
  try {
    action();
    return true;
  } catch (const Error& e) {
    host.setError(e.what());
    return false;
  }
}

// A section's title, under a separator.
void section(const char* title);

// PanelsFile.cpp: what the file panel holds between frames.
struct FileUi {
  explicit FileUi(std::filesystem::path recentFile) : recent(std::move(recentFile)) {}
  char path[512] = "";                         // "##path", opened by "Open"
  char statePath[512] = "tessera-state.json";  // "##state": "Save state" / "Load"
  viewer::RecentFiles recent;                  // the "recent" combo, newest first
  // The command line's file and what it chose (--series, --time,
  // --channel): the DICOM series holds for every file, the time point and
  // channel for that file only.
  std::string commandLineFile;
  session::OpenOptions commandLine;
  session::OpenOptions optionsFor(const std::string& spec) const;
};

// Opens `spec` to explore it in the view (Session::openInView), remembers
// it in the recent list (a file or folder, not a generated volume) and, when
// `channels` asks, shows a store's channels together (openChannels). An
// error goes to the error line as "<message> (the previous volume stays)"
// and a file that is gone leaves the recent list.
void openVolume(session::Session& session, FileUi& ui, PanelHost& host, const std::string& spec,
                bool channels = true);
// A store with several channels shown together (session::ChannelView),
// except a series played over bricks (--bricks), which plays the one
// channel it was opened at.
void openChannels(session::Session& session, const FileUi& ui, PanelHost& host,
                  const std::string& spec);
// The file panel: the volume's description, "##path" + "Open", the
// "recent" combo, "##state" + "Save state" / "Load", the error line.
void panelFile(session::Session& session, FileUi& ui, PanelHost& host);

// PanelsTime.cpp: a time point chosen on the slider that was not read yet,
// shown by stepTime once it is.
struct TimeUi {
  std::optional<int> asked;
};
// Once per window frame, before the panels: the playback's step
// (Session::stepPlayback at `nowMs`), or the time point asked for on the
// slider once read. True when another time point is shown (host.viewChanged
// was called); an unreadable time point stops playback, named on the error
// line.
bool stepTime(session::Session& session, TimeUi& ui, PanelHost& host, double nowMs);
// The time panel of a series: "time point" (a slider), "Play" / "Pause"
// (started at `nowMs`) and "per second" (the rate).
void panelTime(session::Session& session, TimeUi& ui, PanelHost& host, double nowMs);

// PanelsChannels.cpp: the channel list of `view` (open): per channel a
// visibility checkbox (ID path: i, "##visible"), a colour swatch ("##colour")
// and its window (i, "window", "##min" / "##max"); the mode combo ("mode")
// and "Show one channel". Each widget calls the view's setter.
void panelChannels(session::ChannelView& view, PanelHost& host);

// PanelsExplore.cpp: what the exploring panel holds between frames.
struct ExploreUi {
  bool fourUp = true;        // "four views (L)": the slice views beside the 3D view
  bool sliceColour = false;  // "slices in TF colour (C)"
  // "zoom swaps levels and the grid view": the exploration's zoom swap
  // (session::Exploration::keepZoom).
  bool zoomSwitchesGrid = false;
  double viewPixels = 0.0;  // the 3D view's height in pixels (the zoom policy's view)
};
using session::Follow;  // how the camera follows a swap of the 3D view's volume
// The exploring steps (session::Exploration) shown in the session's view;
// nothing happens while the volume is not explored. An error goes to the
// error line; a step shown calls host.viewChanged().
void showOverview(session::Session& session, PanelHost& host, Follow follow = Follow::Fill);
void viewPickedRegion(session::Session& session, PanelHost& host);
// The grid view starts at the grid point nearest the crosshair.
void enterGrid(session::Session& session, PanelHost& host);
void gridMove(session::Session& session, PanelHost& host, lod::ViewMove move);
// The exploring panel: "region side", "View region (V)", "Grid view (G)",
// "Overview (O)", the grid's moves, "four views (L)", "slices in TF colour
// (C)" and the zoom stages with their switch.
void panelExplore(session::Session& session, ExploreUi& ui, PanelHost& host);

// PanelsStyle.cpp: what the look's panels hold between frames.
struct StyleUi {
  char tfPath[512] = "transfer-function.json";  // "##tfpath": "Save" / "Load"
  char labelPath[512] = "labels.txt";           // "##labeltable": "load table"
  bool logHistogram = true;
  bool showCropBox = false;       // the crop box's handles in the 3D view
  std::string tf = "mr-default";  // the command line's TF, back when labels go off
};
// The look's panels over the session's view (viewer::Viewer): the TF
// editor ("preset" combo, points, "Save" / "Load"), "Window / level"
// ("window", "level", "Full range"), "Rendering" ("mode", "technique",
// "quality", the step, sampling, "opacity x"), "Shading", "Clipping" and
// "Labels". An action's error goes to the error line.
void panelTransferFunction(session::Session& session, StyleUi& ui, PanelHost& host);
void panelWindowLevel(viewer::Viewer& view);
void panelRendering(viewer::Viewer& view, PanelHost& host);
void panelShading(viewer::Viewer& view);
void panelClipping(viewer::Viewer& view, StyleUi& ui);
void panelLabels(viewer::Viewer& view, StyleUi& ui, PanelHost& host);

// PanelsOverlay.cpp: what the overlay panel holds between frames.
struct OverlayUi {
  char path[512] = "";
  char table[512] = "";                      // ImGui's buffer of controls.table
  session::OverlayControls controls;         // session/OverlayPanel.h: what the actions take
  const session::Overlay* synced = nullptr;  // the overlay the controls show
  std::string dropped;                       // dropped while a volume is open: overlay or replace?
  std::vector<std::string> pendingDrops;     // PanelsDrop.cpp: handed over by the drop callback
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

// PanelsDrop.cpp: the window's drop callback (gpu::GlfwWindow::onDrop)
// hands the paths dropped, in GLFW's order, to filesDropped; they wait in
// ui.pendingDrops until the frame's handleDrops, after the window's events:
// one path is offerDrop's; two are a volume and its overlay, the first
// opened (host.openFile) and the second offered over it once it opened;
// more than two: the first two so, the rest named on the error line as not
// opened.
void filesDropped(OverlayUi& ui, const std::vector<std::string>& paths);
void handleDrops(session::Session& session, OverlayUi& ui, PanelHost& host);

}  // namespace tessera::desktop
