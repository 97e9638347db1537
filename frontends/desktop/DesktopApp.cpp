// `tessera view`'s window: start-up from the command line's options, the
// frame loop (input, panels, the 3D and slice views, Dear ImGui) and the
// window's layout. The window and its OpenGL ES context are the gpu layer's
// (gpu::GlfwWindow); what the panels and keys do lives in the files named in
// DesktopApp.h.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include "DesktopApp.h"
#include "cli/Commands.h"
#include "tessera/core/Image.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/DeviceSession.h"
#include "tessera/gpu/Draw.h"
#include "tessera/render/LabelTable.h"
#include "tessera/session/Settings.h"

namespace tessera::desktop {

namespace {

// The panel at the left edge; the views share the rest (Tiles).
Tiles layoutTiles(const DesktopApp& ds, int ww, int wh) {
  const float x0 = kPanelWidth, x1 = static_cast<float>(ww), h = static_cast<float>(wh);
  Tiles t;
  if (!ds.explore.fourUp) {
    t.view3d = {{x0, 0.0f}, {x1, h}};
    return t;
  }
  const float xm = std::floor(0.5f * (x0 + x1)), ym = std::floor(0.5f * h);
  t.slice[0] = {{x0, 0.0f}, {xm, ym}};
  t.view3d = {{xm, 0.0f}, {x1, ym}};
  t.slice[2] = {{x0, ym}, {xm, h}};
  t.slice[1] = {{xm, ym}, {x1, h}};
  return t;
}

// The control panel at the window's left edge.
void drawPanel(DesktopApp& ds, int windowHeight, double nowMs) {
  session::Session& s = *ds.session;
  beginControlPanel(static_cast<float>(windowHeight));
  panelFile(s, ds.files, ds);
  panelTime(s, ds.time, ds, nowMs);
  if (channelsShown(ds)) panelChannels(s.channelView(), ds);
  panelExplore(s, ds.explore, ds);
  panelOverlay(s, ds.overlayUi, ds);
  viewer::Viewer& v = ds.view();
  const bool labelsFirst = v.labelsOn();  // the list before the TF it drives
  if (labelsFirst) panelLabels(v, ds.style, ds);
  panelTransferFunction(s, ds.style, ds);
  panelWindowLevel(v);
  panelRendering(v, ds);
  panelShading(v);
  panelClipping(v, ds.style);
  if (!labelsFirst) panelLabels(v, ds.style, ds);
  ImGui::Separator();
  ImGui::TextWrapped("%s", ds.status.c_str());
  ImGui::End();
}

// --screenshot: the window after --frames frames, then the session ends.
void takeScreenshot(DesktopApp& ds, int fbw, int fbh) {
  Image shot(fbw, fbh);
  gpu::clearErrors();  // ImGui's GL backend may leave some
  gpu::bindFramebuffer(0, {0, 0, fbw, fbh});
  gpu::readPixelsRgba8({0, 0, fbw, fbh}, shot.rgba().data());
  shot.flipVertically();
  for (std::size_t i = 3; i < shot.rgba().size(); i += 4) shot.rgba()[i] = 255;
  shot.writePng(ds.options.screenshot);
  const viewer::FrameStats& fs = ds.view().lastFrame();
  std::printf("wrote %s (%dx%d) after %d frames; last volume frame %.0f ms at %dx%d\n",
              ds.options.screenshot.c_str(), fbw, fbh, ds.frame, fs.ms, fs.renderWidth,
              fs.renderHeight);
  ds.window->requestClose();
}

// The 3D view's rectangle in framebuffer pixels, GL's origin bottom-left.
struct PixelRect {
  glm::ivec2 origin;
  int width, height;
};
PixelRect toPixels(const Rect& r, double scale, int framebufferHeight) {
  const int x0 = static_cast<int>(std::lround(r.p0.x * scale));
  const int x1 = static_cast<int>(std::lround(r.p1.x * scale));
  const int y0 = static_cast<int>(std::lround(r.p0.y * scale));
  const int y1 = static_cast<int>(std::lround(r.p1.y * scale));
  return {{x0, framebufferHeight - y1}, std::max(1, x1 - x0), std::max(1, y1 - y0)};
}

// One pass of the event loop: input, panel, volume, ImGui, screenshot, swap.
void runFrame(DesktopApp& ds) {
  ds.window->pollEvents();
  handleDrops(*ds.session, ds.overlayUi, ds);
  const glm::ivec2 fb = ds.window->framebufferSize(), win = ds.window->windowSize();
  const double scale = win.x > 0 ? static_cast<double>(fb.x) / win.x : 1.0;
  const Tiles tiles = layoutTiles(ds, win.x, win.y);
  const PixelRect view = toPixels(tiles.view3d, scale, fb.y);
  ds.explore.viewPixels = view.height;

  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  // A playing time series moves on when its next time point is due and read.
  const double now = steadyNowMs();
  if (stepTime(*ds.session, ds.time, ds, now)) ++ds.timePointsShown;
  handleViewInput(ds, tiles.view3d, scale);
  handleSliceInput(ds, tiles);
  handleShortcuts(ds);
  handleArrowKeys(ds, tiles);
  updateOverlay(ds);
  drawPanel(ds, win.y, now);
  const bool channels = drawChannelView(ds, tiles.view3d, view.width, view.height);
  const bool streamed = !channels && drawStreamedFrames(ds, tiles.view3d, view.width, view.height);
  drawDropOffer(*ds.session, ds.overlayUi, ds);
  for (int t = 0; t < 3 && ds.explore.fourUp; ++t) drawSliceTile(ds, ds.slices[t], tiles.slice[t]);
  drawHelpOverlay(ds, kPanelWidth, static_cast<float>(win.x), static_cast<float>(win.y));
  const EdgeLabels labels = ds.view().orientationLabels();
  drawEdgeLetters(labels.left, labels.right, labels.top, labels.bottom, tiles.view3d.p0,
                  tiles.view3d.p1);
  ImGui::Render();
  gpu::bindFramebuffer(0, {0, 0, fb.x, fb.y});
  gpu::clearColor(glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  if (!channels && !streamed) drawVolumeView(ds, view.origin, view.width, view.height);
  gpu::setViewport({0, 0, fb.x, fb.y});
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

  ++ds.frame;
  if (!ds.options.screenshot.empty() && ds.frame >= ds.options.frames && !ds.view().refining() &&
      playbackDone(ds)) {
    if (ds.session->series() && ds.session->playback().playing()) printPlayback(ds);
    takeScreenshot(ds, fb.x, fb.y);
  }
  ds.window->swapBuffers();
}

// The command line's view: the transfer function, the volume, the camera,
// the rendering settings, where exploring starts and a label volume.
void applyOptions(DesktopApp& ds, const ViewOptions& o) {
  std::string recentError;
  try {
    ds.files.recent.load();
  } catch (const Error& e) {
    recentError = e.what();
    std::fprintf(stderr, "tessera view: %s\n", e.what());
  }
  ds.showHelp = o.helpOverlay;
  ds.view().tfEditor().setTransferFunction(TransferFunction::fromPresetOrFile(o.tf));
  ds.session->settings().tfIsDefault = !o.tfGiven;
  if (o.bricks) ds.session->settings().layout = "bricks";
  ds.files.commandLineFile = o.file;
  ds.files.commandLine.series = o.series;
  ds.files.commandLine.time = o.time;
  ds.files.commandLine.channel = o.channel;
  ds.style.tf = o.tf;
  openVolume(*ds.session, ds.files, ds, o.file.empty() ? app::defaultVolumeSpec() : o.file, false);
  if (!ds.error.empty() && !ds.view().hasVolume()) throw InputError(ds.error);
  if (o.bricks && ds.error.empty() && !ds.session->streamedSeries()) {
    throw InputError("--bricks: " + ds.view().description() +
                     " is not an OME-Zarr store with a t axis (a series is what the view plays "
                     "over bricks)");
  }
  // What is left is the recent list's trouble (unreadable, or not written):
  // shown in the panel, while errors of the options below end the command.
  const std::string recentTrouble = ds.error.empty() ? recentError : ds.error;
  ds.error.clear();
  ds.view().camera().azimuthDeg = o.azimuth;
  ds.view().camera().elevationDeg = o.elevation;
  ds.view().settings().shading = app::shadingFrom(o.shading);
  ds.view().settings().clipping = app::clippingFrom(o.clipping);
  ds.style.showCropBox = ds.view().settings().clipping.cropped();
  ds.view().settings().mode = session::parseRenderMode(o.projection);
  startExploring(ds, o);
  if (o.labelVolume()) {
    ds.view().setLabels(o.labels.empty() ? render::LabelTable::defaultFor(ds.view().volume())
                                         : render::LabelTable::load(o.labels));
    std::snprintf(ds.style.labelPath, sizeof ds.style.labelPath, "%s", o.labels.c_str());
  }
  app::openFusion(*ds.session, o.fusion);
  if (!o.state.empty()) loadState(ds, o.state);
  if (!o.file.empty()) openChannels(*ds.session, ds.files, ds, o.file);
  if (o.play > 0.0) {
    if (!ds.session->series())
      throw InputError("--play: " + ds.view().description() + " is not a time series");
    ds.session->playback().setFps(o.play);
    ds.playStartMs = steadyNowMs();
    ds.session->playback().play(ds.playStartMs);
  }
  ds.error = recentTrouble;
}

// Dear ImGui bound to the window and its context for the loop's lifetime
// (its GL objects go before the window does).
struct ImGuiOnWindow {
  ImGuiOnWindow(gpu::GlfwWindow& window, bool es3) {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;
    ImGui::StyleColorsDark();
    ImGui_ImplGlfw_InitForOpenGL(window.handle(), true);
    ImGui_ImplOpenGL3_Init(es3 ? "#version 300 es" : "#version 100");
  }
  ~ImGuiOnWindow() {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
  }
  ImGuiOnWindow(const ImGuiOnWindow&) = delete;
  ImGuiOnWindow& operator=(const ImGuiOnWindow&) = delete;
};

}  // namespace

void runView(const ViewOptions& o) {
  gpu::GlfwWindow::Options window;
  app::parseSize(o.size, window.width, window.height);
  const gpu::DeviceProfile profile = gpu::DeviceProfile::find(o.profile);
  window.api = profile.api;
  DesktopApp ds(o, std::make_unique<gpu::GlfwWindow>(window), profile.api == gpu::ApiLevel::Gles3);
  ds.session = std::make_unique<session::Session>(gpu::borrowDevice(ds.context(), profile));
  // ES 3 keeps the frame in a cache between window frames, where a full-quality
  // frame can be refined strip by strip; ES 2 redraws every window frame.
  ds.view().progressive = ds.es3;
  ds.window->onDrop(
      [&ds](const std::vector<std::string>& paths) { filesDropped(ds.overlayUi, paths); });
  applyOptions(ds, o);
  const ImGuiOnWindow imgui(*ds.window, ds.es3);
  while (!ds.window->shouldClose()) runFrame(ds);
  if (!o.saveState.empty()) {
    ds.session->saveState(o.saveState);
    std::printf("wrote %s (the session's state)\n", o.saveState.c_str());
  }
}

}  // namespace tessera::desktop
