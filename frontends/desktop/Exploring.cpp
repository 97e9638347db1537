// Where the desktop viewer's exploring starts (--layout, --crosshair,
// --pick, --mode: the exploring panel's steps, PanelsExplore.cpp), the 3D
// view's lines, and the window following the view (DesktopApp's
// PanelHost::viewChanged and stateLoaded).
#include <string>

#include "DesktopApp.h"

namespace tessera::desktop {

// The 3D view's extra lines: exploring's, then the crop box with its handles.
void updateOverlay(DesktopApp& ds) {
  viewer::Viewer& v = ds.view();
  v.extraLines.clear();
  if (!v.hasVolume()) return;
  if (ds.exploring()) v.extraLines = ds.exploration().lines(v.volume().extent());
  if (ds.style.showCropBox) {
    const auto lines =
        viewer::CropHandles::lines(v.settings().clipping, v.volume().extent(), ds.crop.dragging());
    v.extraLines.insert(v.extraLines.end(), lines.begin(), lines.end());
  }
}

// The window follows the 3D view: slice views made again (their geometry
// too: another volume may have other dims), lines made again.
void DesktopApp::viewChanged() {
  for (auto& tile : slices) {
    tile.geometry.reset();
    tile.key.clear();
  }
  updateOverlay(*this);
}

void DesktopApp::stateLoaded() {
  style.showCropBox = view().settings().clipping.cropped();
  viewChanged();
}

void loadState(DesktopApp& ds, const std::string& path) {
  ds.session->loadState(path);
  ds.stateLoaded();
}

// --layout, --crosshair, --pick and --mode: the exploring state to start in.
void startExploring(DesktopApp& ds, const ViewOptions& o) {
  if (o.layout != "four" && o.layout != "single") {
    throw InputError("--layout '" + o.layout + "': expected four or single");
  }
  ds.explore.fourUp = o.layout == "four";
  if (!o.crosshair.empty()) {
    if (o.crosshair.size() != 3) throw InputError("--crosshair takes three voxel indices X Y Z");
    const glm::ivec3 c(o.crosshair[0], o.crosshair[1], o.crosshair[2]);
    const glm::ivec3 d = ds.exploration().dims();
    if (glm::any(glm::lessThan(c, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(c, d))) {
      throw InputError("--crosshair is outside the volume's voxels 0.." + std::to_string(d.x - 1) +
                       ", 0.." + std::to_string(d.y - 1) + ", 0.." + std::to_string(d.z - 1));
    }
    ds.exploration().explorer().setCrosshair(c);
  }
  if (o.regionSide > 0) ds.exploration().explorer().setRegionSide(o.regionSide);
  if (!(o.zoom > 0.0)) throw InputError("--zoom must be > 0");
  ds.view().camera().zoom = o.zoom;
  ds.explore.zoomSwitchesGrid = o.zoomGrid;
  if (o.pick)
    ds.exploration().pick(
        ds.exploration().explorer().regionAt(ds.exploration().explorer().crosshair()));
  if (o.mode == "region") {
    viewPickedRegion(*ds.session, ds);
  } else if (o.mode == "grid") {
    enterGrid(*ds.session, ds);
  } else if (o.mode != "overview") {
    throw InputError("--mode '" + o.mode + "': expected overview, region or grid");
  }
  if (!ds.error.empty()) throw InputError(ds.error);
  updateOverlay(ds);
}

}  // namespace tessera::desktop
