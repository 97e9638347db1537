// Exploring a volume larger than the device holds, through viewer::Explorer:
// the overview level, a picked region or a grid block at native resolution,
// and the lines that show them. Each step is one small function, so that a
// session object can take them over without the panels changing.
#include <cstdio>
#include <filesystem>
#include <utility>

#include "DesktopApp.h"
#include "tessera/render/LabelTable.h"
#include "tessera/session/VolumePyramid.h"

namespace tessera::desktop {

namespace {

// The lines the overview shows: the region or grid block and the crosshair.
void addExploreLines(DesktopApp& ds) {
  viewer::Viewer& v = *ds.viewer;
  v.extraLines.clear();
  if (!ds.explorer || !v.hasVolume()) return;
  const glm::vec4 red(1.0f, 0.25f, 0.2f, 1.0f), cross(1.0f, 0.85f, 0.2f, 1.0f);
  const glm::dvec3 extent = v.volume().extent();
  auto add = [&](const std::vector<render::OverlayLine>& lines) {
    v.extraLines.insert(v.extraLines.end(), lines.begin(), lines.end());
  };
  if (ds.mode == DesktopApp::Mode::Overview) {
    const glm::ivec3 dims = ds.explorer->dims();
    if (ds.picked) add(viewer::boxLines(*ds.picked, dims, extent, red));
    if (ds.gridBlock) {
      add(viewer::boxLines(*ds.gridBlock, dims, extent, glm::vec4(0.25f, 0.85f, 0.95f, 1.0f)));
    }
    add(viewer::crosshairLines(ds.explorer->crosshair(), dims, extent, cross));
  } else if (ds.shown) {
    // The crosshair within the native sub-volume, where it falls inside it.
    const glm::ivec3 c = ds.explorer->crosshair() - ds.shown->begin;
    if (glm::all(glm::greaterThanEqual(c, glm::ivec3(0))) &&
        glm::all(glm::lessThan(c, ds.shown->size()))) {
      v.extraLines = viewer::crosshairLines(c, ds.shown->size(), extent, cross);
    }
  }
}

// Shows `volume` (the whole volume or `box` of it) in the 3D view.
void showIn3D(DesktopApp& ds, Volume volume, const std::string& name,
              const std::optional<lod::VoxelBox>& box, Follow follow) {
  const Camera before = ds.viewer->camera();
  const std::optional<lod::VoxelBox> from = ds.shown;
  std::optional<render::LabelTable> labels;
  if (ds.viewer->labelsOn()) labels = ds.viewer->labelTable();
  ds.viewer->setVolume(std::move(volume), name);
  if (labels) ds.viewer->setLabels(std::move(*labels));  // the same table on the region
  Camera& c = ds.viewer->camera();
  if (follow == Follow::Keep) {
    const Camera kept = viewer::cameraAcrossSwap(before, from, box, ds.explorer->dims(),
                                                 ds.explorer->source().shape().spacing());
    c.target = kept.target;
    c.zoom = kept.zoom;
  } else {
    c.zoom = follow == Follow::Fill ? 1.0 : before.zoom;
  }
  c.azimuthDeg = before.azimuthDeg;
  c.elevationDeg = before.elevationDeg;
}

std::string levelLabel(const std::string& label, int level) {
  return label + (level > 0 ? " (level " + std::to_string(level) + ")" : "");
}

// Reads `box` at native resolution (one bounded read) into the 3D view.
void showNative(DesktopApp& ds, const lod::VoxelBox& box, DesktopApp::Mode mode, Follow follow) {
  ds.zoomSwap.reset();  // the keys decide now
  const bool shown = reportErrors(ds, [&] {
    showIn3D(ds, ds.explorer->readRegion(box), ds.volumeLabel + " " + boxText(box) + " (native)",
             box, follow);
  });
  if (shown) {
    ds.mode = mode;
    ds.shown = box;
    if (mode == DesktopApp::Mode::Grid) ds.gridBlock = box;
  }
  updateOverlay(ds);
}

}  // namespace

// The 3D view's extra lines: exploring's, then the crop box with its handles.
void updateOverlay(DesktopApp& ds) {
  addExploreLines(ds);
  viewer::Viewer& v = *ds.viewer;
  if (ds.showCropBox && v.hasVolume()) {
    const auto lines =
        viewer::CropHandles::lines(v.settings().clipping, v.volume().extent(), ds.crop.dragging());
    v.extraLines.insert(v.extraLines.end(), lines.begin(), lines.end());
  }
}

std::string boxText(const lod::VoxelBox& b) {
  char t[96];
  std::snprintf(t, sizeof t, "%d:%d,%d:%d,%d:%d", b.begin.x, b.end.x, b.begin.y, b.end.y, b.begin.z,
                b.end.z);
  return t;
}

// Loads a volume as a pyramid (viewer/Explorer.h reads regions and slices
// from it; a store or head:WxHxD is read box by box) and shows its
// overview. Throws, leaving the previous volume, when it cannot.
void loadVolume(DesktopApp& ds, const std::string& spec) {
  const session::VolumePyramid pyramid =
      session::openVolumePyramid(spec, {.series = ds.options.series});
  const gpu::DeviceLimits& limits = ds.viewer->limits();
  auto explorer =
      std::make_unique<viewer::Explorer>(pyramid.source, viewer::regionBudgetBytes(limits));
  const int level = explorer->overviewLevel(viewer::overviewVoxelBudget(limits));
  auto overview = std::make_shared<const Volume>(explorer->readLevel(level));
  const std::string label = std::filesystem::path(spec).filename().string();
  ds.viewer->setVolume(*overview, levelLabel(label, level));
  ds.explorer = std::move(explorer);
  ds.overview = std::move(overview);
  ds.overviewLevel = level;
  ds.volumeLabel = label;
  ds.mode = DesktopApp::Mode::Overview;
  ds.picked.reset();
  ds.shown.reset();
  ds.gridBlock.reset();
  ds.exploreNote.clear();
  for (auto& tile : ds.slices) {
    tile.geometry.reset();
    tile.key.clear();
  }
  updateOverlay(ds);
}

void showOverview(DesktopApp& ds, Follow follow) {
  if (!ds.overview) return;
  ds.zoomSwap.reset();  // made again from the overview (panelExplore)
  const bool shown = reportErrors(ds, [&] {
    showIn3D(ds, *ds.overview, levelLabel(ds.volumeLabel, ds.overviewLevel), std::nullopt, follow);
  });
  if (shown) {
    ds.mode = DesktopApp::Mode::Overview;
    ds.shown.reset();
    ds.exploreNote.clear();
  }
  updateOverlay(ds);
}

void viewPickedRegion(DesktopApp& ds) {
  if (!ds.explorer) return;
  if (!ds.picked) ds.picked = ds.explorer->regionAt(ds.explorer->crosshair());
  showNative(ds, *ds.picked, DesktopApp::Mode::Region, Follow::Fill);
}

// The grid view starts at the grid point nearest the crosshair (the zoom
// swap, viewer/ZoomSwap.h, picks the point the view is centred on itself).
void enterGrid(DesktopApp& ds) {
  if (!ds.explorer) return;
  lod::GridNavigator& g = ds.explorer->grid();
  const glm::dvec3 voxel = glm::dvec3(ds.explorer->crosshair()) + 0.5;
  const glm::dvec3 c = voxel / glm::dvec3(g.cellSize());
  g.moveTo(glm::clamp(glm::ivec3(glm::round(c)), glm::ivec3(0), g.cells()));
  ds.exploreNote = g.describe(g.point());
  showNative(ds, g.blockBox(g.point()), DesktopApp::Mode::Grid, Follow::Fill);
}

void gridMove(DesktopApp& ds, lod::ViewMove move) {
  lod::GridNavigator& g = ds.explorer->grid();
  const lod::GridMove m = lod::viewMoveToGridMove(ds.viewer->camera().basis(), move);
  const lod::MoveResult r = g.apply(m);
  const std::string named = std::string(lod::viewMoveName(move)) + " = " + m.name();
  if (!r.moved) {
    ds.exploreNote = named + ": " + r.reason;
    return;
  }
  ds.exploreNote = named + "; " + g.describe(g.point());
  showNative(ds, g.blockBox(g.point()), DesktopApp::Mode::Grid, Follow::Centre);
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
  if (ds.mode != DesktopApp::Mode::Overview || (ds.zoomSwap && ds.zoomSwapKey == stagesKey)) {
    return;
  }
  try {
    ds.zoomSwap = std::make_unique<viewer::ZoomSwap>(ds.context(), *ds.explorer, stages);
    ds.zoomSwap->keepLevel(ds.overviewLevel, ds.overview);
    ds.zoomSwap->setLabel(ds.volumeLabel);
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
    const glm::ivec3 d = ds.explorer->dims();
    if (glm::any(glm::lessThan(c, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(c, d))) {
      throw InputError("--crosshair is outside the volume's voxels 0.." + std::to_string(d.x - 1) +
                       ", 0.." + std::to_string(d.y - 1) + ", 0.." + std::to_string(d.z - 1));
    }
    ds.explorer->setCrosshair(c);
  }
  if (o.regionSide > 0) ds.explorer->setRegionSide(o.regionSide);
  if (!(o.zoom > 0.0)) throw InputError("--zoom must be > 0");
  ds.viewer->camera().zoom = o.zoom;
  ds.zoomSwitchesGrid = o.zoomGrid;
  if (o.pick) ds.picked = ds.explorer->regionAt(ds.explorer->crosshair());
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
