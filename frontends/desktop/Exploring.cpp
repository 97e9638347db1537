// The desktop viewer's steps of exploring (keys, buttons and --mode): each
// asks session::Exploration for the step and has it shown in the 3D view;
// the overview, region, grid and their lines are the session's.
#include <utility>

#include "DesktopApp.h"

namespace tessera::desktop {

namespace {

// Shows a step of the exploration; its error goes to the panel.
void showStep(DesktopApp& ds, const session::ExploreStep& step) {
  reportErrors(ds, [&] { ds.exploration().show(ds.view(), step); });
  updateOverlay(ds);
}

}  // namespace

// The 3D view's extra lines: exploring's, then the crop box with its handles.
void updateOverlay(DesktopApp& ds) {
  viewer::Viewer& v = ds.view();
  v.extraLines.clear();
  if (!v.hasVolume()) return;
  if (ds.exploring()) v.extraLines = ds.exploration().lines(v.volume().extent());
  if (ds.showCropBox) {
    const auto lines =
        viewer::CropHandles::lines(v.settings().clipping, v.volume().extent(), ds.crop.dragging());
    v.extraLines.insert(v.extraLines.end(), lines.begin(), lines.end());
  }
}

// Opens a volume as a pyramid in the session's view (a store or
// head:WxHxD is read box by box) and shows its overview. Throws, leaving
// the previous volume, when it cannot.
void loadVolume(DesktopApp& ds, const std::string& spec) {
  session::OpenOptions open;
  open.series = ds.options.series;
  // --time and --channel choose within the file given on the command line.
  if (spec == ds.options.file) {
    open.time = ds.options.time;
    open.channel = ds.options.channel;
  }
  ds.session->openInView(spec, open);
  for (auto& tile : ds.slices) {
    tile.geometry.reset();
    tile.key.clear();
  }
  updateOverlay(ds);
}

void showOverview(DesktopApp& ds, Follow follow) {
  if (!ds.exploring()) return;
  reportErrors(ds, [&] { ds.exploration().showOverview(ds.view(), follow); });
  updateOverlay(ds);
}

void viewPickedRegion(DesktopApp& ds) {
  if (ds.exploring()) showStep(ds, ds.exploration().pickedRegion(Follow::Fill));
}

// The grid view starts at the grid point nearest the crosshair (the zoom
// swap, viewer/ZoomSwap.h, picks the point the view is centred on itself).
void enterGrid(DesktopApp& ds) {
  if (ds.exploring())
    showStep(ds, ds.exploration().enterGrid(ds.exploration().explorer().crosshair()));
}

void gridMove(DesktopApp& ds, lod::ViewMove move) {
  if (const auto step = ds.exploration().move(move, ds.view().camera().basis()))
    showStep(ds, *step);
}

// The exploration's zoom swap follows the panel's switch (made again for
// new stages: another volume or view size; `stagesKey` names them).
void keepZoomSwap(DesktopApp& ds, const std::vector<lod::ZoomStage>& stages,
                  const std::string& stagesKey) {
  reportErrors(
      ds, [&] { ds.exploration().keepZoom(ds.context(), ds.zoomSwitchesGrid, stages, stagesKey); });
}

// --layout, --crosshair, --pick and --mode: the exploring state to start in.
void startExploring(DesktopApp& ds, const ViewOptions& o) {
  if (o.layout != "four" && o.layout != "single") {
    throw InputError("--layout '" + o.layout + "': expected four or single");
  }
  ds.fourUp = o.layout == "four";
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
  ds.zoomSwitchesGrid = o.zoomGrid;
  if (o.pick)
    ds.exploration().pick(
        ds.exploration().explorer().regionAt(ds.exploration().explorer().crosshair()));
  if (o.mode == "region") {
    viewPickedRegion(ds);
  } else if (o.mode == "grid") {
    enterGrid(ds);
  } else if (o.mode != "overview") {
    throw InputError("--mode '" + o.mode + "': expected overview, region or grid");
  }
  if (!ds.error.empty()) throw InputError(ds.error);
  updateOverlay(ds);
}

}  // namespace tessera::desktop
