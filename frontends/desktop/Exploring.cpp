// The desktop viewer's steps of exploring (keys, buttons and --mode): each
// asks session::Exploration for the step and has it shown in the 3D view;
// the overview, region, grid and their lines are the session's.
#include <filesystem>
#include <utility>

#include "DesktopApp.h"
#include "tessera/session/VolumePyramid.h"

namespace tessera::desktop {

namespace {

// Shows a step of the exploration; its error goes to the panel.
void showStep(DesktopApp& ds, const session::ExploreStep& step) {
  ds.zoomSwap.reset();  // the keys decide now
  reportErrors(ds, [&] { ds.explore->show(*ds.viewer, step); });
  updateOverlay(ds);
}

}  // namespace

// The 3D view's extra lines: exploring's, then the crop box with its handles.
void updateOverlay(DesktopApp& ds) {
  viewer::Viewer& v = *ds.viewer;
  v.extraLines.clear();
  if (!v.hasVolume()) return;
  if (ds.explore) v.extraLines = ds.explore->lines(v.volume().extent());
  if (ds.showCropBox) {
    const auto lines =
        viewer::CropHandles::lines(v.settings().clipping, v.volume().extent(), ds.crop.dragging());
    v.extraLines.insert(v.extraLines.end(), lines.begin(), lines.end());
  }
}

// Loads a volume as a pyramid (a store or head:WxHxD is read box by box)
// and shows its overview. Throws, leaving the previous volume, when it
// cannot.
void loadVolume(DesktopApp& ds, const std::string& spec) {
  const session::VolumePyramid pyramid =
      session::openVolumePyramid(spec, {.series = ds.options.series});
  const gpu::DeviceLimits& limits = ds.viewer->limits();
  auto explore = std::make_unique<session::Exploration>(
      pyramid.source, viewer::regionBudgetBytes(limits), viewer::overviewVoxelBudget(limits),
      std::filesystem::path(spec).filename().string());
  ds.viewer->setVolume(*explore->overview(), explore->overviewName());
  ds.explore = std::move(explore);
  for (auto& tile : ds.slices) {
    tile.geometry.reset();
    tile.key.clear();
  }
  updateOverlay(ds);
}

void showOverview(DesktopApp& ds, Follow follow) {
  if (!ds.explore) return;
  ds.zoomSwap.reset();  // made again from the overview (panelExplore)
  reportErrors(ds, [&] { ds.explore->showOverview(*ds.viewer, follow); });
  updateOverlay(ds);
}

void viewPickedRegion(DesktopApp& ds) {
  if (ds.explore) showStep(ds, ds.explore->pickedRegion(Follow::Fill));
}

// The grid view starts at the grid point nearest the crosshair (the zoom
// swap, viewer/ZoomSwap.h, picks the point the view is centred on itself).
void enterGrid(DesktopApp& ds) {
  if (ds.explore) showStep(ds, ds.explore->enterGrid(ds.explore->explorer().crosshair()));
}

void gridMove(DesktopApp& ds, lod::ViewMove move) {
  if (const auto step = ds.explore->move(move, ds.viewer->camera().basis())) showStep(ds, *step);
}

// The zoom swap follows the panel's switch: gone while it is off or the
// volume has one stage; made from the overview (after a manual mode change:
// once back there) and made again for new stages (another volume or view
// size; `stagesKey` names them).
void keepZoomSwap(DesktopApp& ds, const std::vector<lod::ZoomStage>& stages,
                  const std::string& stagesKey) {
  if (!ds.zoomSwitchesGrid || stages.size() < 2) {
    ds.zoomSwap.reset();
    return;
  }
  if (ds.explore->mode() != session::ExploreMode::Overview ||
      (ds.zoomSwap && ds.zoomSwapKey == stagesKey)) {
    return;
  }
  try {
    ds.zoomSwap = std::make_unique<viewer::ZoomSwap>(ds.context(), ds.explore->explorer(), stages);
    ds.zoomSwap->keepLevel(ds.explore->overviewLevel(), ds.explore->overview());
    ds.zoomSwap->setLabel(ds.explore->label());
    ds.zoomSwapKey = stagesKey;
  } catch (const Error& e) {
    ds.error = e.what();
  }
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
    const glm::ivec3 d = ds.explore->dims();
    if (glm::any(glm::lessThan(c, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(c, d))) {
      throw InputError("--crosshair is outside the volume's voxels 0.." + std::to_string(d.x - 1) +
                       ", 0.." + std::to_string(d.y - 1) + ", 0.." + std::to_string(d.z - 1));
    }
    ds.explore->explorer().setCrosshair(c);
  }
  if (o.regionSide > 0) ds.explore->explorer().setRegionSide(o.regionSide);
  if (!(o.zoom > 0.0)) throw InputError("--zoom must be > 0");
  ds.viewer->camera().zoom = o.zoom;
  ds.zoomSwitchesGrid = o.zoomGrid;
  if (o.pick) ds.explore->pick(ds.explore->explorer().regionAt(ds.explore->explorer().crosshair()));
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
