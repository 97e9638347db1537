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
#include "tessera/lod/InCoreMultiresSource.h"

namespace tessera::web {

namespace {

// A frame's time step for the fade, at most this: a fade spans at least
// 250 / 100 + 1 frames however slow a frame is (a software rasteriser's
// 300 ms frame would otherwise end it in one: a pop).
constexpr double kMaxFadeStepMs = 100.0;

}  // namespace

// True while the zoom swap drives the viewer (a volume loaded since ends it).
bool WebSession::zoomActive() {
  if (!zoom_.swap) return false;
  const viewer::Viewer& v = viewer();
  if (v.hasVolume() && v.volumeName() == zoom_.shownName) return true;
  zoom_ = ZoomView();
  return false;
}

const Volume* WebSession::zoomOverview() {
  return zoomActive() ? zoom_.whole.get() : nullptr;
}

std::optional<lod::VoxelBox> WebSession::zoomBox() {
  return zoomActive() ? zoom_.swap->shownBox() : std::nullopt;
}

void WebSession::zoomStop() {
  if (!zoomActive()) {
    zoomForget();
    return;
  }
  viewer::Viewer& v = viewer();
  const Camera before = v.camera();
  const ValueRange window = v.window();
  const std::optional<lod::VoxelBox> box = zoom_.swap->shownBox();
  std::shared_ptr<const Volume> whole = zoom_.whole;
  const std::string name = zoom_.name;
  v.setVolume(Volume(*whole), name);  // throws with the zoom swap still on
  zoomForget();
  v.setWindow(window);
  v.camera() = viewer::cameraAcrossSwap(before, box, std::nullopt, whole->dims(), whole->spacing());
}

double WebSession::zoomFrame(int width, int height) {
  viewer::Viewer& v = viewer();
  const double now = emscripten_get_now();
  const double dt =
      zoom_.lastFrameMs < 0.0 ? 0.0 : std::min(now - zoom_.lastFrameMs, kMaxFadeStepMs);
  zoom_.lastFrameMs = now;
  zoom_.swap->frame(v, dt, width, height);
  zoom_.shownName = v.volumeName();
  return emscripten_get_now() - now;
}

// Stages for a view `viewPixels` high; `overviewVoxels` > 0 replaces the
// profile's overview budget and `blockVoxels` > 0 its native block budget
// (e.g. to see all three stages on a small volume).
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
  ZoomView z;
  z.whole = std::make_shared<const Volume>(v.volume());
  z.name = v.volumeName();
  auto source = std::make_shared<const lod::InCoreMultiresSource>(z.whole);
  const gpu::DeviceLimits& limits = v.limits();
  const std::uint64_t bpv = bytesPerVoxel(z.whole->type());
  const std::uint64_t blockBytes = blockVoxels > 0.0 ? static_cast<std::uint64_t>(blockVoxels) * bpv
                                                     : viewer::regionBudgetBytes(limits);
  z.explorer = std::make_unique<viewer::Explorer>(source, blockBytes);
  z.mediumLevel =
      z.explorer->overviewLevel(overviewVoxels > 0.0 ? static_cast<std::uint64_t>(overviewVoxels)
                                                     : viewer::overviewVoxelBudget(limits));
  const std::vector<lod::ZoomStage> stages =
      viewer::zoomStagesFor(*z.explorer, z.mediumLevel, std::max(1, viewPixels));
  if (stages.size() < 2) {
    throw InputError("zoom swap: " + z.name + " is too small to have coarser levels");
  }
  z.swap = std::make_unique<viewer::ZoomSwap>(context(), *z.explorer, stages);
  z.swap->keepLevel(0, z.whole);
  z.swap->setLabel(z.name);
  z.shownName = v.volumeName();
  zoom_ = std::move(z);
}

}  // namespace tessera::web
