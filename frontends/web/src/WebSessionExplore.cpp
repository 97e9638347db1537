// The session's slice views, bread-slice region and grid view (frontends/web/slices.js,
// frontends/web/grid.js). Slices of the loaded volume are drawn on the CPU with
// core/SliceImage (the same pixels and patient-direction letters as
// `tessera slice`); the region (Schultz 2016 §7.4) is a box of the volume at
// native resolution shown as the 3D view (lod::copyBox, what `tessera render
// --region` reads for a file), the overview kept to return to; the grid view
// (Schultz 2016 §7.3) moves a 2x2x2 block of cells with lod::GridNavigator
// (its points, classes, legal moves and the moves chosen by the view
// direction are all its own) and shows the block the way the region is.
#include <algorithm>
#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "WebSession.h"
#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/gpu/MemoryLedger.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/render/OverlayRenderer.h"

namespace tessera::web {

namespace {

std::string dimsText(const glm::ivec3& d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

}  // namespace

// Another volume opened through the session ends its exploration there
// (Session::setVolume); the zoom swap's stages carry their own names.
bool WebSession::regionShown() {
  if (!explore() || explore()->mode() == session::ExploreMode::Overview) return false;
  const viewer::Viewer& v = viewer();
  return v.hasVolume() && v.volumeName() == explore()->shownName();
}

const Volume& WebSession::sliceShape() {
  if (storeOverview()) return theStore().store().shape();
  return overviewVolume();
}

const Volume& WebSession::overviewVolume() {
  if (const Volume* store = storeOverview()) return *store;
  if (const Volume* whole = zoomOverview()) return *whole;
  viewer::Viewer& v = viewer();
  if (!storeOverview() && regionShown()) return *explore()->overview();
  if (!v.hasVolume()) throw InputError("no volume is loaded");
  return v.volume();
}

std::string WebSession::overviewName() {
  if (storeOverview()) return theStore().storage().describe();
  if (regionShown()) return explore()->label();
  if (zoomOverview()) return zoomName();
  return viewer().volumeName();
}

// The largest cube side (<= 256, as Schultz's bread-slice textures) whose
// voxels fit the profile: its 3D texture size (or a WebGL 1 atlas of
// side x side tiles in a 2D texture) and what the texture budget leaves
// next to the overview's upload. The planner still has the last word.
std::pair<int, std::string> WebSession::defaultRegionSide(const Volume& volume) {
  const gpu::DeviceLimits& l = viewer().limits();
  const std::uint64_t bpv = bytesPerVoxel(volume.type());
  const gpu::MemoryLedger& ledger = context().ledger();
  const std::uint64_t used = ledger.totalBytes();
  const std::uint64_t left =
      ledger.budget() == 0 ? 0 : (ledger.budget() > used ? ledger.budget() - used : 1);
  for (int s = 256; s >= 16; s -= 16) {
    const std::uint64_t bytes = std::uint64_t(s) * s * s * bpv;
    const int tiles = static_cast<int>(std::ceil(std::sqrt(double(s))));
    const bool fitsTexture =
        l.max3DTextureSize > 0 ? s <= l.max3DTextureSize : s * tiles <= l.max2DTextureSize;
    if (fitsTexture && (ledger.budget() == 0 || bytes <= left)) {
      std::string why = s == 256 ? "256³ voxels (Schultz 2016's bread-slice texture)"
                                 : std::to_string(s) + "³ voxels: what the " + l.profile +
                                       " profile's texture size and budget allow";
      return {s, why};
    }
  }
  return {16, "16³ voxels: the " + l.profile + " profile leaves little texture memory"};
}

// The store's levels at the time point the session shows (its t axis
// played, in core or over bricks, or its channels' together), so that the
// slices and the readout show what the 3D view shows; the open selection's
// otherwise.
const FetchedZarrSource& WebSession::storeSliceSource() {
  ZarrStoreView& z = theStore();
  const int open = z.store().selection().time;
  const int t = session_->series() ? session_->timePoint() : open;
  if (t < 0 || t == open) return z.source();
  return *z.sourceAt(t);
}

// A store's slice (indices of level 0) is read at the finest level whose
// slice has at most `maxPixels` pixels, as one slab with bounded reads;
// until that slab's chunks have arrived the coarsest level (in memory)
// stands in and `pending` is set. A chunk that keeps failing leaves the
// coarse slice, with `note` naming it. A store's time point other than
// the one opened (its t axis played) is read the same from its own levels,
// its coarsest level's slab standing in (held with the time point).
SliceResult WebSession::slice(int axis, int index, bool colour, double maxPixels) {
  if (axis < 0 || axis > 2) throw InputError("slice: the axis must be 0, 1 or 2");
  const Volume& volume = sliceShape();
  SliceResult out;
  out.frame = sliceFrame(volume.direction(), axis);
  const SliceFrame& f = out.frame;
  const glm::ivec3 d = volume.dims();
  if (index < 0 || index >= d[axis]) {
    throw InputError("slice: index " + std::to_string(index) +
                     " is outside 0:" + std::to_string(d[axis]));
  }
  out.raster = sliceRaster(f, d, volume.spacing());
  out.count = d[axis];
  out.oriented = !volume.geometrySource().empty();
  Image& image = slices_.images[axis];
  out.image = &image;
  viewer::Viewer& v = viewer();
  const Volume* store = storeOverview();
  // A store's window until a region of it is shown (the viewer's then).
  const ValueRange window = store && !v.hasVolume() ? volume.window() : v.window();
  const TransferFunction* tf = v.sliceColours(colour);
  if (!store) {
    image = sliceImage(volume, f, index, window, tf);
    if (const session::Overlay* o = session_->overlay()) {
      session::fuseSliceImage(image, volume, f, index, *o);  // docs/fusion.md
    }
    return out;
  }
  const FetchedZarrSource& src = storeSliceSource();
  // The open time point's coarsest level is in memory (storeOverview).
  const bool opened = &src == &theStore().source();
  const int coarsest = src.levelCount() - 1;
  int level = 0;
  while (level < coarsest && maxPixels > 0.0) {
    const lod::LevelInfo li = src.levelInfo(level);
    const SliceRaster rl = sliceRaster(f, li.dims, li.spacing);
    if (double(rl.width) * rl.height <= maxPixels) break;
    ++level;
  }
  // Level l's slice through level-0 slice `index` (levels need not halve).
  const auto indexAt = [&](int l) {
    const int n = src.levelInfo(l).dims[axis];
    return std::clamp(static_cast<int>((index + 0.5) * n / d[axis]), 0, n - 1);
  };
  const auto slabAt = [&](int l) {
    lod::VoxelBox slab{{0, 0, 0}, src.levelInfo(l).dims};
    slab.begin[axis] = indexAt(l);
    slab.end[axis] = slab.begin[axis] + 1;
    return slab;
  };
  const auto render = [&](int l) {
    const lod::LevelInfo li = src.levelInfo(l);
    const viewer::SliceGeometry g(li.dims, li.spacing, volume.direction(), axis);
    return g.render(src, l, indexAt(l), window, tf);
  };
  bool ready = false;
  try {
    ready = (level == coarsest && opened) || src.prefetch(level, slabAt(level));
  } catch (const Error& e) {
    out.note = e.what();
  }
  if (ready && !(level == coarsest && opened)) {
    image = render(level);
  } else {
    out.pending = out.note.empty() && level < coarsest;
    level = coarsest;
    if (opened) {
      image = sliceImage(*store, f, indexAt(coarsest), window, tf);
    } else if (src.resident(coarsest, slabAt(coarsest))) {
      image = render(coarsest);
    } else {
      // Let go by the chunk cache since the time point was read: wanted,
      // and no image of another time point shown meanwhile.
      src.prefetch(coarsest, slabAt(coarsest));
      image = Image(std::max(1, image.width()), std::max(1, image.height()));
      out.pending = true;
    }
  }
  out.level = level;
  if (const session::Overlay* o = session_->overlay()) {
    session::fuseSliceImage(image, src, level, f, indexAt(level), *o);  // docs/fusion.md
  }
  return out;
}

// A store's level-0 voxel once its chunk has arrived (the slices fetch it
// when they show level 0; the readout asks for nothing), the coarsest
// level's otherwise; of the time point the session shows. NaN outside.
double WebSession::voxelValue(int x, int y, int z) {
  const glm::ivec3 d = sliceShape().dims();
  if (!(x >= 0 && y >= 0 && z >= 0 && x < d.x && y < d.y && z < d.z)) return std::nan("");
  const Volume* store = storeOverview();
  if (!store) return overviewVolume().valueAt(x, y, z);
  const FetchedZarrSource& src = storeSliceSource();
  const lod::VoxelBox voxel{{x, y, z}, {x + 1, y + 1, z + 1}};
  if (src.resident(0, voxel)) return src.readBox(0, voxel).valueAt(0, 0, 0);
  const int top = src.levelCount() - 1;
  const glm::ivec3 td = src.levelInfo(top).dims;
  const glm::ivec3 c =
      glm::clamp(glm::ivec3((glm::dvec3(x, y, z) + 0.5) * glm::dvec3(td) / glm::dvec3(d)),
                 glm::ivec3(0), td - 1);
  if (&src == &theStore().source()) return store->valueAt(c.x, c.y, c.z);
  const lod::VoxelBox coarse{c, c + 1};
  if (src.resident(top, coarse)) return src.readBox(top, coarse).valueAt(0, 0, 0);
  return std::nan("");
}

// The exploration of what the slices show, made anew for another overview
// (a file's shares the viewer's voxels) or another grid cell asked for.
session::Exploration& WebSession::exploration(int cellSide) {
  const Volume& volume = sliceShape();
  const std::string key = overviewKey(volume);
  if (!explore() || exploreKey_ != key) {
    if (storeOverview()) {
      // The store draws its own overview: none is read here. Of the time
      // point shown (its t axis played), which the session carries the
      // exploration over to as it plays.
      session_->exploreDrawn(theStore().storage().describe());
    } else {
      // The file's: the session's volume, shared.
      session_->endExploration();
      session_->exploration();
    }
    exploreKey_ = key;
    askedCell_ = -1;  // the grid below is set for it
  }
  const int asked = cellSide < 0 ? std::max(askedCell_, 0) : cellSide;
  if (asked != askedCell_) {
    explore()->setGrid(asked > 0 ? lod::GridNavigator(volume.dims(), glm::ivec3(asked))
                                 : defaultGrid(volume));
    askedCell_ = asked;
  }
  return *explore();
}

// Ends past the volume are clamped; an empty box or one that starts outside
// is an error. The window, the TF, the zoom and the overview stay.
void WebSession::showRegion(lod::VoxelBox box) {
  zoomStop();  // the region replaces the whole volume, not a level of it
  session::Exploration& e = exploration();
  e.show(viewer(), e.region(box, session::Follow::Centre));
}

// With the overview's camera and the current window; the region stays
// known to the page, which draws it as a highlighted box.
void WebSession::returnToOverview() {
  if (regionShown()) explore()->showOverview(viewer(), session::Follow::Back);
}

// A point at continuous voxel coordinates p of the overview lies at model
// point p * spacing + offset of the volume the view shows.
std::optional<VoxelProjection> WebSession::projection(int width, int height) {
  viewer::Viewer& v = viewer();
  if (width <= 0 || height <= 0) return std::nullopt;
  VoxelProjection p;
  if (storeOverview()) {
    // The slices' voxels are the store's level-0 voxels (sliceShape); its
    // frames are drawn in level 0's model frame (ZarrStoreView::frame), a
    // region of it by the viewer (a box of level 0 placed where it lies).
    const Volume& shape = theStore().store().shape();
    const bool inRegion = regionShown();
    const glm::dvec3 extent = inRegion ? v.volume().extent() : shape.extent();
    p.spacing = shape.spacing();
    p.offset = -0.5 * extent - (inRegion ? glm::dvec3(explore()->shown()->begin) * shape.spacing()
                                         : glm::dvec3(0.0));
    // The store's frames frame the viewer's camera on the store's shape.
    Camera c = v.camera();
    if (!inRegion) c.frame(shape);
    p.mvp = render::viewProjection(c, double(width) / height, 0.5 * glm::length(extent));
    return p;
  }
  if (!v.hasVolume()) return std::nullopt;
  const Volume& shownVolume = v.volume();
  p.spacing = shownVolume.spacing();
  p.offset = -0.5 * shownVolume.extent();
  if (regionShown()) p.offset -= glm::dvec3(explore()->shown()->begin) * p.spacing;
  if (const Volume* whole = zoomOverview()) {
    // A level spans the whole volume's box; the native block is a box of
    // level 0.
    if (const auto box = zoomBox()) {
      p.offset -= glm::dvec3(box->begin) * p.spacing;
    } else {
      p.spacing = shownVolume.extent() / glm::dvec3(whole->dims());
    }
  }
  const double radius = 0.5 * glm::length(shownVolume.extent());
  p.mvp = render::viewProjection(v.camera(), double(width) / height, radius);
  return p;
}

// ---- the grid view

// The grid is over the slices' voxels (sliceShape: a store's level 0, where
// its blocks are read like its regions; a file's overview volume).
std::string WebSession::overviewKey(const Volume& v) {
  const glm::ivec3 d = v.dims();
  if (storeOverview()) return "store:" + theStore().storage().describe() + "|" + dimsText(d);
  return overviewName() + "|" + dimsText(d);
}

// True while the 3D view shows the block the grid put in (not a region
// picked since, nor the overview, nor another file).
bool WebSession::gridShown() {
  return regionShown() && explore()->mode() == session::ExploreMode::Grid;
}

bool WebSession::gridStoreWanted() {
  return storeOverview() && explore() && explore()->pending() &&
         explore()->pending()->mode == session::ExploreMode::Grid;
}

// The default cell: cubic, a multiple of 16 voxels, as large as possible
// while the 2x2x2 block fits the region's default side cubed (what the
// profile's texture size and budget allow, at most 256³), and no larger
// than a quarter of the longest axis (Schultz's 4x4x4 split), so that a
// volume that fits the budget whole still has a grid to move on.
lod::GridNavigator WebSession::defaultGrid(const Volume& volume) {
  const int side = defaultRegionSide(volume).first;
  const glm::ivec3 d = volume.dims();
  const int budgetCell =
      lod::GridNavigator::forBudget(d, std::uint64_t(side) * side * side, 16).cellSize().x;
  const int quarter = (std::max({d.x, d.y, d.z}) + 3) / 4;
  const int splitCell = std::max(16, (quarter + 15) / 16 * 16);
  return lod::GridNavigator(d, glm::ivec3(std::min(budgetCell, splitCell)));
}

// Shows a grid step as the 3D view (a store's block is read like its
// region: the page fetches exactly its level-0 chunks, then calls
// tessera_zarr_region_show and tessera_grid_store_shown).
void WebSession::showGridBlock(const session::ExploreStep& step) {
  if (storeOverview()) return;
  try {
    explore()->show(viewer(), step);
  } catch (const std::exception& e) {
    throw InputError("grid view: " + std::string(e.what()));
  }
}

// At the grid point nearest the centre of voxel `voxel` of the overview.
void WebSession::gridEnter(int cellSide, const glm::ivec3& voxel) {
  zoomStop();  // the grid view's block replaces the whole volume
  session::Exploration& e = exploration(cellSide);
  showGridBlock(e.enterGrid(voxel));  // the crosshair is in the slices' voxels, as the grid
}

int WebSession::gridMove(int viewMove) {
  if (viewMove < 0 || viewMove > 5) throw InputError("grid view: moves are 0..5");
  if (!gridShown() && !gridStoreWanted()) {
    throw InputError("grid view: not in the grid view (press G)");
  }
  const auto step = exploration().move(kViewMoves[viewMove], viewer().camera().basis());
  if (!step) return 0;
  showGridBlock(*step);
  return 1;
}

// The grid point goes back to where it was before the enter or move that
// asked for the store's block.
void WebSession::gridStoreFailed() {
  if (gridStoreWanted()) explore()->failed("the block could not be read");
}

void WebSession::gridStoreShown() {
  if (!gridShown() || !storeOverview()) {
    throw InputError("grid view: the store's block has not been read");
  }
}

}  // namespace tessera::web
