#include "tessera/session/Exploration.h"

#include <algorithm>
#include <limits>
#include <utility>

#include <glm/common.hpp>
#include <glm/vector_relational.hpp>
#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/render/LabelTable.h"
#include "tessera/viewer/Viewer.h"

namespace tessera::session {

namespace {

constexpr int kStateVersion = 1;

nlohmann::json boxJson(const std::optional<lod::VoxelBox>& box) {
  if (!box) return nullptr;
  return {{box->begin.x, box->begin.y, box->begin.z}, {box->end.x, box->end.y, box->end.z}};
}

std::optional<lod::VoxelBox> boxFrom(const nlohmann::json& j) {
  if (j.is_null()) return std::nullopt;
  const auto v = [&](int i) {
    return glm::ivec3(j.at(i).at(0).get<int>(), j.at(i).at(1).get<int>(), j.at(i).at(2).get<int>());
  };
  return lod::VoxelBox{v(0), v(1)};
}

glm::ivec3 ivec3From(const nlohmann::json& j) {
  return {j.at(0).get<int>(), j.at(1).get<int>(), j.at(2).get<int>()};
}

// A volume in memory as a pyramid of one level: a region or block is a
// box of it, and no coarser level is ever made.
std::shared_ptr<const lod::MultiresSource> levelZeroOnly(std::shared_ptr<const Volume> volume) {
  return std::make_shared<const lod::InCoreMultiresSource>(std::move(volume),
                                                           std::numeric_limits<int>::max());
}

// Swaps `volume` into the view with the user's window and label table kept
// (a region or the overview is the same data, seen again); throws with the
// old volume kept.
void swapKeepingLook(viewer::Viewer& view, Volume volume, const std::string& name) {
  const bool had = view.hasVolume();
  const ValueRange window = had ? view.window() : volume.window();
  std::optional<render::LabelTable> labels;
  if (had && view.labelsOn()) labels = view.labelTable();
  view.setVolume(std::move(volume), name);
  if (labels) view.setLabels(std::move(*labels));
  view.setWindow(window);
}

}  // namespace

const char* exploreModeName(ExploreMode mode) {
  static constexpr const char* kNames[] = {"overview", "region", "grid"};  // in enum order
  return kNames[static_cast<int>(mode)];
}

std::string boxText(const lod::VoxelBox& b) {
  const auto range = [&](int a) {
    return std::to_string(b.begin[a]) + ":" + std::to_string(b.end[a]);
  };
  return range(0) + "," + range(1) + "," + range(2);
}

Exploration::Exploration(std::shared_ptr<const lod::MultiresSource> source,
                         std::uint64_t regionBudgetBytes, std::uint64_t overviewVoxels,
                         std::string label)
    : explorer_(std::make_unique<viewer::Explorer>(std::move(source), regionBudgetBytes)),
      regionBudgetBytes_(regionBudgetBytes),
      label_(std::move(label)) {
  if (overviewVoxels > 0) {
    overviewLevel_ = explorer_->overviewLevel(overviewVoxels);
    overview_ = std::make_shared<const Volume>(explorer_->readLevel(overviewLevel_));
  }
}

Exploration::Exploration(std::shared_ptr<const Volume> volume, std::uint64_t regionBudgetBytes,
                         std::string label)
    : explorer_(std::make_unique<viewer::Explorer>(levelZeroOnly(volume), regionBudgetBytes)),
      regionBudgetBytes_(regionBudgetBytes),
      label_(std::move(label)),
      overview_(std::move(volume)) {}

std::string Exploration::overviewName() const {
  return label_ + (overviewLevel_ > 0 ? " (level " + std::to_string(overviewLevel_) + ")" : "");
}

lod::VoxelBox Exploration::clampBox(lod::VoxelBox box, const std::string& what) const {
  const glm::ivec3 d = dims();
  const char* names = "xyz";
  for (int a = 0; a < 3; ++a) {
    if (box.begin[a] < 0 || box.begin[a] >= d[a] || box.end[a] <= box.begin[a]) {
      throw InputError(what + ": " + names[a] + " range " + std::to_string(box.begin[a]) + ":" +
                       std::to_string(box.end[a]) +
                       " is empty or starts outside 0:" + std::to_string(d[a]));
    }
    box.end[a] = std::min(box.end[a], d[a]);
  }
  return box;
}

ExploreStep Exploration::region(const lod::VoxelBox& box, Follow follow) {
  const lod::VoxelBox b = clampBox(box, "region");
  picked_ = b;
  pending_ = ExploreStep{b, ExploreMode::Region, follow};
  return *pending_;
}

ExploreStep Exploration::pickedRegion(Follow follow) {
  if (!picked_) picked_ = explorer_->regionAt(explorer_->crosshair());
  return region(*picked_, follow);
}

ExploreStep Exploration::enterGrid(glm::ivec3 voxel) {
  lod::GridNavigator& g = explorer_->grid();
  pendingFrom_ = g.point();
  const glm::dvec3 c = (glm::dvec3(voxel) + 0.5) / glm::dvec3(g.cellSize());
  g.moveTo(glm::clamp(glm::ivec3(glm::round(c)), glm::ivec3(0), g.cells()));
  note_ = "grid point " + g.describe(g.point());
  refused_ = false;
  pending_ = ExploreStep{g.blockBox(g.point()), ExploreMode::Grid, Follow::Fill};
  return *pending_;
}

std::optional<ExploreStep> Exploration::move(lod::ViewMove move, const glm::dmat3& basis) {
  lod::GridNavigator& g = explorer_->grid();
  const lod::GridMove m = lod::viewMoveToGridMove(basis, move);
  const std::string what = std::string(lod::viewMoveName(move)) + " = " + m.name();
  const glm::ivec3 from = g.point();
  const lod::MoveResult r = g.apply(m);
  if (!r.moved) {
    note_ = what + " refused: " + r.reason;
    refused_ = true;
    return std::nullopt;
  }
  pendingFrom_ = from;
  note_ = what + ": grid point " + g.describe(g.point());
  refused_ = false;
  pending_ = ExploreStep{g.blockBox(g.point()), ExploreMode::Grid, Follow::Centre};
  return pending_;
}

void Exploration::setGrid(lod::GridNavigator grid) {
  explorer_->grid() = std::move(grid);
  gridBlock_.reset();
  note_.clear();
  refused_ = false;
  if (mode_ == ExploreMode::Grid) mode_ = ExploreMode::Region;  // its block, no longer a grid's
}

Volume Exploration::read(const ExploreStep& step) const {
  return explorer_->readRegion(step.box);
}

void Exploration::show(viewer::Viewer& view, const ExploreStep& step) {
  endZoom();  // the step decides now
  pending_ = step;
  try {
    showIn(view, read(step), step);
  } catch (const Error& e) {
    failed(e.what());
    throw;
  }
}

Camera Exploration::followed(const Camera& before, const Camera& framed, Follow follow,
                             const std::optional<lod::VoxelBox>& to) const {
  if (follow == Follow::Back) return overviewCamera_;
  Camera c = framed;
  if (follow == Follow::Keep) {
    const Camera kept =
        viewer::cameraAcrossSwap(before, shown_, to, dims(), explorer_->source().shape().spacing());
    c.target = kept.target;
    c.zoom = kept.zoom;
  } else {
    c.zoom = follow == Follow::Centre ? before.zoom : 1.0;
  }
  c.projection = before.projection;
  c.azimuthDeg = before.azimuthDeg;
  c.elevationDeg = before.elevationDeg;
  return c;
}

void Exploration::showIn(viewer::Viewer& view, Volume volume, const ExploreStep& step) {
  const Camera before = view.camera();
  const std::string name = label_ + " region " + boxText(step.box);
  swapKeepingLook(view, std::move(volume), name);
  if (mode_ == ExploreMode::Overview) overviewCamera_ = before;
  view.camera() = followed(before, view.camera(), step.follow, step.box);
  mode_ = step.mode;
  shown_ = step.box;
  shownName_ = name;
  if (step.mode == ExploreMode::Grid) gridBlock_ = step.box;
  pending_.reset();
}

void Exploration::failed(const std::string& why) {
  if (pending_ && pending_->mode == ExploreMode::Grid) {
    lod::GridNavigator& g = explorer_->grid();
    g.moveTo(pendingFrom_);
    note_ = why + "; back at grid point " + g.describe(pendingFrom_);
    refused_ = true;
  }
  pending_.reset();
}

void Exploration::showOverview(viewer::Viewer& view, Follow follow) {
  if (!overview_) throw InputError(label_ + ": no overview volume was read");
  endZoom();  // made again from the overview when it is still wanted
  if (mode_ == ExploreMode::Overview && view.hasVolume() && view.volumeName() == overviewName()) {
    return;
  }
  const Camera before = view.camera();
  swapKeepingLook(view, Volume(*overview_), overviewName());  // a copy: the overview stays here
  // Back from the overview itself: nothing was left, the camera stays.
  if (follow != Follow::Back || mode_ != ExploreMode::Overview) {
    view.camera() = followed(before, view.camera(), follow, std::nullopt);
  }
  overviewShown();
}

void Exploration::makeLevels() {
  if (!overview_ || overviewLevel_ != 0 || explorer_->source().levelCount() > 1) return;
  auto source = std::make_shared<const lod::InCoreMultiresSource>(overview_);
  if (source->levelCount() < 2) return;  // too small to have coarser levels
  endZoom();                             // it refers to the explorer replaced here
  auto next = std::make_unique<viewer::Explorer>(std::move(source), regionBudgetBytes_);
  next->setCrosshair(explorer_->crosshair());
  next->setRegionSide(explorer_->regionSide());
  next->grid() = explorer_->grid();
  explorer_ = std::move(next);
}

void Exploration::keepZoom(gpu::GlContext& context, bool wanted,
                           const std::vector<lod::ZoomStage>& stages, const std::string& key) {
  if (!wanted || stages.size() < 2) {
    endZoom();
    return;
  }
  if (mode_ != ExploreMode::Overview || (zoom_ && zoomKey_ == key)) return;
  auto swap = std::make_unique<viewer::ZoomSwap>(context, *explorer_, stages);
  if (overview_) swap->keepLevel(overviewLevel_, overview_);
  swap->setLabel(label_);
  zoom_ = std::move(swap);
  zoomKey_ = key;
}

void Exploration::endZoom() {
  zoom_.reset();
  zoomKey_.clear();
}

lod::ZoomFrame Exploration::zoomFrame(viewer::Viewer& view, double dtMs, int width, int height,
                                      unsigned framebuffer, glm::ivec2 origin) {
  if (!zoom_) throw InputError(label_ + ": the zoom swap is not running");
  try {
    const lod::ZoomFrame frame = zoom_->frame(view, dtMs, width, height, framebuffer, origin);
    shownBy(zoom_->shownBox(), ExploreMode::Grid);
    return frame;
  } catch (const Error&) {
    endZoom();
    throw;
  }
}

void Exploration::overviewShown() {
  mode_ = ExploreMode::Overview;
  shown_.reset();
  shownName_.clear();
  pending_.reset();
}

void Exploration::shownBy(const std::optional<lod::VoxelBox>& box, ExploreMode mode) {
  mode_ = box ? mode : ExploreMode::Overview;
  shown_ = box;
  if (box && mode == ExploreMode::Grid) gridBlock_ = box;
}

std::vector<render::OverlayLine> Exploration::lines(glm::dvec3 extent) const {
  std::vector<render::OverlayLine> out;
  const auto add = [&](const std::vector<render::OverlayLine>& more) {
    out.insert(out.end(), more.begin(), more.end());
  };
  const glm::ivec3 cross = explorer_->crosshair();
  if (mode_ == ExploreMode::Overview || !shown_) {
    if (picked_) add(viewer::boxLines(*picked_, dims(), extent, kRegionColour));
    if (gridBlock_) add(viewer::boxLines(*gridBlock_, dims(), extent, kGridBlockColour));
    add(viewer::crosshairLines(cross, dims(), extent, kCrosshairColour));
    return out;
  }
  // The crosshair within the native box, where it falls inside it.
  const glm::ivec3 c = cross - shown_->begin;
  if (glm::all(glm::greaterThanEqual(c, glm::ivec3(0))) &&
      glm::all(glm::lessThan(c, shown_->size()))) {
    add(viewer::crosshairLines(c, shown_->size(), extent, kCrosshairColour));
  }
  return out;
}

nlohmann::json Exploration::state() const {
  const lod::GridNavigator& g = explorer_->grid();
  const glm::ivec3 d = dims(), c = explorer_->crosshair(), cell = g.cellSize(), p = g.point();
  return {{"version", kStateVersion},
          {"dims", {d.x, d.y, d.z}},
          {"mode", exploreModeName(mode_)},
          {"crosshair", {c.x, c.y, c.z}},
          {"region_side", explorer_->regionSide()},
          {"picked", boxJson(picked_)},
          {"shown", boxJson(shown_)},
          {"grid", {{"cell", {cell.x, cell.y, cell.z}}, {"point", {p.x, p.y, p.z}}}}};
}

std::optional<ExploreStep> Exploration::restore(const nlohmann::json& j) {
  try {
    if (j.at("version").get<int>() != kStateVersion) {
      throw InputError("exploration state version " + j.at("version").dump() + ": expected " +
                       std::to_string(kStateVersion));
    }
    if (ivec3From(j.at("dims")) != dims()) {
      throw InputError("exploration state: it is of a volume of " + j.at("dims").dump() +
                       " voxels, not of " + label_);
    }
    const glm::ivec3 cell = ivec3From(j.at("grid").at("cell"));
    if (cell != explorer_->grid().cellSize()) setGrid(lod::GridNavigator(dims(), cell));
    explorer_->grid().moveTo(ivec3From(j.at("grid").at("point")));
    explorer_->setCrosshair(ivec3From(j.at("crosshair")));
    explorer_->setRegionSide(j.at("region_side").get<int>());
    const std::optional<lod::VoxelBox> picked = boxFrom(j.at("picked"));
    picked_ = picked ? std::optional(clampBox(*picked, "exploration state: picked")) : std::nullopt;
    const std::string mode = j.at("mode").get<std::string>();
    const std::optional<lod::VoxelBox> shown = boxFrom(j.at("shown"));
    if (mode == exploreModeName(ExploreMode::Overview) || !shown) return std::nullopt;
    const ExploreMode m =
        mode == exploreModeName(ExploreMode::Grid) ? ExploreMode::Grid : ExploreMode::Region;
    if (m == ExploreMode::Region && mode != exploreModeName(ExploreMode::Region)) {
      throw InputError("exploration state: mode '" + mode + "': expected overview, region or grid");
    }
    return ExploreStep{clampBox(*shown, "exploration state: shown"), m, Follow::Fill};
  } catch (const nlohmann::json::exception& e) {
    throw InputError(std::string("exploration state: ") + e.what());
  }
}

}  // namespace tessera::session
