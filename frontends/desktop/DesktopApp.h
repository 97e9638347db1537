#pragma once
// The desktop viewer's state between frames and the functions each of its
// files offers the others. The window and its context come from the gpu
// layer (gpu::GlfwWindow); this front end turns input into viewer calls and
// draws the panels with Dear ImGui.
//
//   ViewCommand.cpp    the subcommand's options (ViewOptions.h); without
//                      GLFW or ImGui, ViewUnavailable.cpp says what to install
//   DesktopApp.cpp     start-up, the frame loop, the window's layout
//   VolumeView.cpp     the 3D view: render when it changed, else blit the cache
//   Input.cpp          keys and mouse on the 3D and slice views, the help overlay
//   Exploring.cpp      where exploring starts (--mode, --crosshair), the view's lines
//   SliceViews.cpp     the three slice views through the crosshair
//   Panels.h           the panels, drawn without a window (file, time,
//                      channels, exploring, overlay, the look; dropped
//                      files): DesktopApp is their PanelHost
//   StreamedSeriesView.cpp a time series played over bricks in the 3D view
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <imgui.h>
#include <glm/vec2.hpp>

#include "Panels.h"
#include "ViewOptions.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/GlfwWindow.h"
#include "tessera/lod/GridNavigator.h"
#include "tessera/lod/MultiresSource.h"
#include "tessera/lod/ZoomLevelPolicy.h"
#include "tessera/session/Exploration.h"
#include "tessera/session/OverlayPanel.h"
#include "tessera/session/Session.h"
#include "tessera/viewer/CropHandles.h"
#include "tessera/viewer/RecentFiles.h"
#include "tessera/viewer/SliceView.h"
#include "tessera/viewer/Viewer.h"

namespace tessera::desktop {

// Everything the desktop viewer holds between frames. The window is the
// first member: destroyed last, after every GL object of its context. It is
// the host of the window-free panels (Panels.h): their errors go to its
// error line, a file they open is opened as the file panel opens one.
struct DesktopApp : PanelHost {
  DesktopApp(const ViewOptions& o, std::unique_ptr<gpu::GlfwWindow> w, bool gles3)
      : window(std::move(w)), options(o), es3(gles3) {}
  void setError(const std::string& message) override { error = message; }
  const std::string& errorLine() const override { return error; }
  void openFile(const std::string& path) override { openVolume(*session, files, *this, path); }
  void overlayChanged() override {
    for (auto& tile : slices) tile.key.clear();  // the slice views mix it in
  }
  void viewChanged() override;  // Exploring.cpp
  void stateLoaded() override;
  std::unique_ptr<gpu::GlfwWindow> window;
  const ViewOptions& options;
  bool es3;
  gpu::GlContext& context() { return window->context(); }
  // The rendering session on the window's context: its view is the 3D
  // view, its exploration (once a volume is open) the slice views', region's
  // and grid's, its state what "Save state" writes.
  std::unique_ptr<session::Session> session;
  viewer::Viewer& view() { return session->view(); }
  bool exploring() const { return session && session->exploring(); }
  session::Exploration& exploration() { return session->exploration(); }
  std::string error;
  std::string status;
  gpu::Framebuffer cache;  // ES 3: the last volume frame, blitted while nothing changes
  std::string cacheKey;
  // Panels.h: what the panels hold between frames.
  FileUi files{viewer::RecentFiles::defaultPath()};
  TimeUi time;
  StyleUi style;
  ExploreUi explore;
  OverlayUi overlayUi;  // the overlay's controls and a dropped file's offer
  int frame = 0;
  // Playback of a time series: time points shown, from the first frame.
  int timePointsShown = 0;
  double playStartMs = -1.0;
  // Over bricks: the last time point shown (its number in timePointsShown)
  // whose frame was drawn complete, and so recorded (--play-record).
  int completeShows = -1;
  bool showHelp = false;
  double lastFrameMs = 0.0;
  // The three slice views: axial, coronal, sagittal.
  struct SliceTile {
    std::string plane;
    std::unique_ptr<viewer::SliceGeometry> geometry;
    gpu::Texture texture;
    std::string key;
    viewer::SliceViewport viewport;
  };
  SliceTile slices[3] = {
      {"axial", {}, {}, "", {}}, {"coronal", {}, {}, "", {}}, {"sagittal", {}, {}, "", {}}};
  int dragTile = -1;          // a slice view being dragged in (-1: none)
  bool dragRegion = false;    // right button: drawing a region box
  glm::dvec2 dragStart{0.0};  // window units
  // The crop box drawn with a handle on each face (viewer/CropHandles.h),
  // while style.showCropBox.
  viewer::CropHandles crop;
};

// A rectangle of the window in ImGui (window) units, top-left origin.
struct Rect {
  ImVec2 p0, p1;
  bool contains(ImVec2 p) const { return p.x >= p0.x && p.y >= p0.y && p.x < p1.x && p.y < p1.y; }
};
// Where the views go right of the panel: one 3D view, or four up (axial
// top-left, 3D top-right, sagittal bottom-left, coronal bottom-right, as
// 3D Slicer's four-up layout).
struct Tiles {
  Rect view3d;
  Rect slice[3];  // axial, coronal, sagittal (empty when not four-up)
};

// Exploring.cpp: where exploring starts, the 3D view's lines.
void startExploring(DesktopApp& ds, const ViewOptions& o);
void updateOverlay(DesktopApp& ds);
// Restores a saved session state (Session::loadState) and what the window
// shows of it (the crop box, the slice views); throws on error.
void loadState(DesktopApp& ds, const std::string& path);
// Milliseconds on a steady clock: the playback's time.
inline double steadyNowMs() {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// A store's channels shown together (session::ChannelView); Panels.h's
// panelChannels draws their list.
inline bool channelsShown(const DesktopApp& ds) {
  return ds.session && ds.session->hasChannelView() && ds.session->channelView().isOpen();
}

// SliceViews.cpp
void drawSliceTile(DesktopApp& ds, DesktopApp::SliceTile& tile, const Rect& r);

// StreamedSeriesView.cpp: a series over bricks (session::StreamedFrames)
// Queues the time point's streamed frame into the 3D view's rectangle;
// false when no series plays over bricks or a region or grid block is
// shown (the viewer's frame is drawn instead).
bool drawStreamedFrames(DesktopApp& ds, const Rect& rect, int viewW, int viewH);
// Whether --play-time-points' time points have been shown (over bricks:
// the last one drawn complete); true without it.
bool playbackDone(const DesktopApp& ds);
// The playback's figures for --screenshot: rate, time points, late ones,
// and the texture and host memory against the profile's budgets.
void printPlayback(const DesktopApp& ds);

// Input.cpp
void handleViewInput(DesktopApp& ds, const Rect& view, double scale);
void handleSliceInput(DesktopApp& ds, const Tiles& tiles);
void handleShortcuts(DesktopApp& ds);
void handleArrowKeys(DesktopApp& ds, const Tiles& tiles);
void drawHelpOverlay(DesktopApp& ds, float x0, float x1, float height);

// VolumeView.cpp
void drawVolumeView(DesktopApp& ds, glm::ivec2 origin, int viewW, int viewH);
// Queues the channels' frame into the 3D view's rectangle; false when no
// channels are shown (the viewer's frame is drawn instead).
bool drawChannelView(DesktopApp& ds, const Rect& rect, int viewW, int viewH);
void drawEdgeLetters(const std::string& left, const std::string& right, const std::string& top,
                     const std::string& bottom, ImVec2 p0, ImVec2 p1);

}  // namespace tessera::desktop
