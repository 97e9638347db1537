// The session's zoom-driven level swap (Schultz 2016 §7.3.1), the desktop
// viewer's viewer::ZoomSwap on the page: zoomed out the 3D view shows a
// coarse level of the loaded volume, then the medium level (the finest that
// fits the profile's overview budget), then, zoomed in far enough, the
// native 2x2x2 grid block around the view's centre; each swap keeps the
// camera (every patient point stays on screen) and cross-fades. The slice
// views, crosshair, region and grid keep working on the whole loaded volume
// (held here while the zoom drives the view); picking a region, entering
// the grid view, labels or another volume hand the view back to the whole
// volume first.
#include <emscripten/emscripten.h>

#include <algorithm>

#include "WebSession.h"
#include "tessera/core/Error.h"

namespace tessera::web {

namespace {

// A frame's time step for the fade, at most this: a fade spans at least
// 250 / 100 + 1 frames however slow a frame is (a software rasteriser's
// 300 ms frame would otherwise end it in one: a pop).
constexpr double kMaxFadeStepMs = 100.0;

}  // namespace

// True while the exploration's zoom swap drives the viewer (another volume
// loaded since came with another exploration, without one).
bool WebSession::zoomActive() {
  return explore() != nullptr && explore()->zoom() != nullptr;
}

const Volume* WebSession::zoomOverview() {
  return zoomActive() ? explore()->overview().get() : nullptr;
}

std::optional<lod::VoxelBox> WebSession::zoomBox() {
  return zoomActive() ? explore()->zoom()->shownBox() : std::nullopt;
}

// The whole volume back in the view, the camera following so that every
// point stays where it was on screen (session::Follow::Keep).
void WebSession::zoomStop() {
  if (!zoomActive()) {
    zoomForget();
    return;
  }
  explore()->showOverview(viewer(), session::Follow::Keep);  // ends the swap
  zoomLastFrameMs_ = -1.0;
}

double WebSession::zoomFrame(int width, int height) {
  const double now = emscripten_get_now();
  const double dt = zoomLastFrameMs_ < 0.0 ? 0.0 : std::min(now - zoomLastFrameMs_, kMaxFadeStepMs);
  zoomLastFrameMs_ = now;
  explore()->zoomFrame(viewer(), dt, width, height);
  return emscripten_get_now() - now;
}

// Stages for a view `viewPixels` high; `overviewVoxels` > 0 replaces the
// profile's overview budget and `blockVoxels` > 0 its native block budget
// (the grid's cells: e.g. to see all three stages on a small volume).
void WebSession::zoomStart(int viewPixels, double overviewVoxels, double blockVoxels) {
  viewer::Viewer& v = viewer();
  if (storeOverview()) {
    throw InputError(
        "zoom swap: an OME-Zarr store already refines with the zoom (its bricks' level "
        "selection); the zoom swap is for files");
  }
  if (v.labelsOn()) {
    throw InputError("zoom swap: not for a label volume (coarser levels would average labels)");
  }
  returnToOverview();
  zoomStop();
  if (!v.hasVolume()) throw InputError("zoom swap: no volume is loaded");
  session::Exploration& e = exploration();
  e.makeLevels();
  if (blockVoxels > 0.0) {
    e.setGrid(viewer::gridForBudget(e.dims(), static_cast<std::uint64_t>(blockVoxels)));
  }
  const gpu::DeviceLimits& limits = v.limits();
  const int medium =
      e.explorer().overviewLevel(overviewVoxels > 0.0 ? static_cast<std::uint64_t>(overviewVoxels)
                                                      : viewer::overviewVoxelBudget(limits));
  const std::vector<lod::ZoomStage> stages =
      viewer::zoomStagesFor(e.explorer(), medium, std::max(1, viewPixels));
  if (stages.size() < 2) {
    throw InputError("zoom swap: " + e.label() + " is too small to have coarser levels");
  }
  e.keepZoom(context(), true, stages, "page");
  zoomMediumLevel_ = medium;
  zoomLastFrameMs_ = -1.0;
}

}  // namespace tessera::web
