// The session's slice views, bread-slice region and grid view (web/slices.js,
// web/grid.js). Slices of the loaded volume are drawn on the CPU with
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

std::string rangeText(const lod::VoxelBox& box, int a) {
  return std::to_string(box.begin[a]) + ":" + std::to_string(box.end[a]);
}

}  // namespace

bool WebSession::regionShown() {
  SliceViews& s = slices_;
  if (!s.overview) return false;
  const viewer::Viewer& v = viewer();
  if (v.hasVolume() && &v.volume() == s.shown && v.volumeName() == s.shownName) return true;
  s.overview.reset();
  s.shown = nullptr;
  return false;
}

const Volume& WebSession::sliceShape() {
  if (storeOverview()) return theStore().store().shape();
  return overviewVolume();
}

const Volume& WebSession::overviewVolume() {
  if (const Volume* store = storeOverview()) return *store;
  if (const Volume* whole = zoomOverview()) return *whole;
  viewer::Viewer& v = viewer();
  if (regionShown()) return *slices_.overview;
  if (!v.hasVolume()) throw InputError("no volume is loaded");
  return v.volume();
}

std::string WebSession::overviewName() {
  if (storeOverview()) return theStore().storage().describe();
  if (regionShown()) return slices_.overviewName;
  if (zoomOverview()) return zoom_.name;
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

// A store's slice (indices of level 0) is read at the finest level whose
// slice has at most `maxPixels` pixels, as one slab with bounded reads;
// until that slab's chunks have arrived the coarsest level (in memory)
// stands in and `pending` is set. A chunk that keeps failing leaves the
// coarse slice, with `note` naming it.
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
    return out;
  }
  const FetchedZarrSource& src = theStore().source();
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
  const lod::LevelInfo li = src.levelInfo(level);
  lod::VoxelBox slab{{0, 0, 0}, li.dims};
  slab.begin[axis] = indexAt(level);
  slab.end[axis] = slab.begin[axis] + 1;
  bool ready = false;
  try {
    ready = level == coarsest || src.prefetch(level, slab);
  } catch (const Error& e) {
    out.note = e.what();
  }
  if (ready && level < coarsest) {
    const viewer::SliceGeometry g(li.dims, li.spacing, volume.direction(), axis);
    image = g.render(src, level, slab.begin[axis], window, tf);
  } else {
    out.pending = out.note.empty() && level < coarsest;
    level = coarsest;
    image = sliceImage(*store, f, indexAt(coarsest), window, tf);
  }
  out.level = level;
  return out;
}

// A store's level-0 voxel once its chunk has arrived (the slices fetch it
// when they show level 0; the readout asks for nothing), the coarsest
// level's otherwise. NaN outside.
double WebSession::voxelValue(int x, int y, int z) {
  const glm::ivec3 d = sliceShape().dims();
  if (!(x >= 0 && y >= 0 && z >= 0 && x < d.x && y < d.y && z < d.z)) return std::nan("");
  const Volume* store = storeOverview();
  if (!store) return overviewVolume().valueAt(x, y, z);
  const FetchedZarrSource& src = theStore().source();
  const lod::VoxelBox voxel{{x, y, z}, {x + 1, y + 1, z + 1}};
  if (src.resident(0, voxel)) return src.readBox(0, voxel).valueAt(0, 0, 0);
  const glm::ivec3 c = glm::clamp(
      glm::ivec3((glm::dvec3(x, y, z) + 0.5) * glm::dvec3(store->dims()) / glm::dvec3(d)),
      glm::ivec3(0), store->dims() - 1);
  return store->valueAt(c.x, c.y, c.z);
}

// Ends past the volume are clamped; an empty box or one that starts outside
// is an error. The window, the TF and the overview stay.
void WebSession::showRegion(lod::VoxelBox box) {
  zoomStop();  // the region replaces the whole volume, not a level of it
  viewer::Viewer& v = viewer();
  SliceViews& s = slices_;
  const bool inRegion = regionShown();
  const Volume& full = overviewVolume();
  const glm::ivec3 d = full.dims();
  const char* names = "xyz";
  for (int a = 0; a < 3; ++a) {
    if (box.begin[a] < 0 || box.begin[a] >= d[a] || box.end[a] <= box.begin[a]) {
      throw InputError(std::string("region: ") + names[a] + " range " + rangeText(box, a) +
                       " is empty or starts outside 0:" + std::to_string(d[a]));
    }
    box.end[a] = std::min(box.end[a], d[a]);
  }
  const ValueRange window = v.window();
  Volume region = lod::copyBox(full, box);
  region.setGeometrySource(full.geometrySource());
  region.setWindow(window);
  const std::string overviewName = inRegion ? s.overviewName : v.volumeName();
  const std::string name = overviewName + " region " + rangeText(box, 0) + "," + rangeText(box, 1) +
                           "," + rangeText(box, 2);
  // The viewer takes its volume by value: the overview is copied out
  // before the region replaces it (kept while the region is shown).
  std::unique_ptr<Volume> overview =
      inRegion ? std::move(s.overview) : std::make_unique<Volume>(full);
  const Camera camera = inRegion ? s.overviewCamera : v.camera();
  try {
    v.setVolume(std::move(region), name);
  } catch (...) {
    if (inRegion) s.overview = std::move(overview);
    throw;
  }
  v.setWindow(window);
  s.overview = std::move(overview);
  s.overviewName = overviewName;
  s.overviewCamera = camera;
  s.region = box;
  s.shown = &v.volume();
  s.shownName = name;
}

// With the overview's camera and the current window; the region stays
// known to the page, which draws it as a highlighted box.
void WebSession::returnToOverview() {
  if (!regionShown()) return;
  viewer::Viewer& v = viewer();
  SliceViews& s = slices_;
  const ValueRange window = v.window();
  // A copy, so that the overview survives an upload that fails.
  v.setVolume(Volume(*s.overview), s.overviewName);
  v.setWindow(window);
  v.camera() = s.overviewCamera;
  s.overview.reset();
  s.shown = nullptr;
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
    const StoreRegion& r = storeRegion_;
    const bool inRegion = r.shown && v.hasVolume();
    const glm::dvec3 extent = inRegion ? v.volume().extent() : shape.extent();
    p.spacing = shape.spacing();
    p.offset =
        -0.5 * extent - (inRegion ? glm::dvec3(r.box.begin) * shape.spacing() : glm::dvec3(0.0));
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
  if (regionShown()) p.offset -= glm::dvec3(slices_.region.begin) * p.spacing;
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
  const GridView& g = grid_;
  if (storeOverview()) {
    const StoreRegion& r = storeRegion_;
    return !g.shownName.empty() && r.shown && g.block && r.box.begin == g.block->begin &&
           r.box.end == g.block->end && viewer().volumeName() == g.shownName;
  }
  return !g.shownName.empty() && regionShown() && slices_.shownName == g.shownName;
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

// Made anew for another volume or another cell side; `cellSide` < 0 keeps
// the current one.
lod::GridNavigator& WebSession::gridFor(const Volume& volume, int cellSide) {
  GridView& g = grid_;
  const std::string key = overviewKey(volume);
  const int asked = cellSide < 0 ? g.askedCell : cellSide;
  if (!g.nav || g.volumeKey != key || g.askedCell != asked) {
    g.nav = asked > 0 ? lod::GridNavigator(volume.dims(), glm::ivec3(asked)) : defaultGrid(volume);
    g.volumeKey = key;
    g.askedCell = asked;
    g.block.reset();
    g.shownName.clear();
    g.note.clear();
    g.refused = false;
  }
  return *g.nav;
}

// Shows `box` of the overview as the 3D view. The view direction and the
// projection stay (the moves are chosen from it); the zoom too on a move,
// 1 on entering (the block fills the view).
void WebSession::showGridBlock(const lod::VoxelBox& box, bool keepZoom) {
  GridView& g = grid_;
  if (storeOverview()) {
    // A store's block is read like its region: the page fetches exactly its
    // level-0 chunks, then calls tessera_grid_store_shown.
    if (!g.storeWanted) {
      g.fromBlock = g.block;
      g.fromShownName = g.shownName;
    }
    g.block = box;
    g.storeWanted = true;
    g.shownName.clear();
    return;
  }
  viewer::Viewer& v = viewer();
  const Camera before = v.camera();
  try {
    showRegion(box);
  } catch (const std::exception& e) {
    throw InputError("grid view: " + std::string(e.what()));
  }
  Camera& c = v.camera();
  c.projection = before.projection;
  c.azimuthDeg = before.azimuthDeg;
  c.elevationDeg = before.elevationDeg;
  c.zoom = keepZoom ? before.zoom : 1.0;
  g.shownName = slices_.shownName;
  g.block = box;
}

// At the grid point nearest the centre of voxel `voxel` of the overview.
void WebSession::gridEnter(int cellSide, const glm::ivec3& voxel) {
  zoomStop();  // the grid view's block replaces the whole volume
  const Volume& volume = sliceShape();
  lod::GridNavigator& nav = gridFor(volume, cellSide);
  // The crosshair is in the slices' voxels, as the grid.
  const glm::dvec3 c = (glm::dvec3(voxel) + 0.5) / glm::dvec3(nav.cellSize());
  if (!grid_.storeWanted) grid_.fromPoint = nav.point();
  nav.moveTo(glm::clamp(glm::ivec3(glm::round(c)), glm::ivec3(0), nav.cells()));
  showGridBlock(nav.blockBox(nav.point()), false);
  grid_.note = "grid point " + nav.describe(nav.point());
  grid_.refused = false;
}

int WebSession::gridMove(int viewMove) {
  if (viewMove < 0 || viewMove > 5) throw InputError("grid view: moves are 0..5");
  if (!gridShown() && !grid_.storeWanted) {
    throw InputError("grid view: not in the grid view (press G)");
  }
  lod::GridNavigator& nav = gridFor(sliceShape(), -1);
  const lod::ViewMove vm = kViewMoves[viewMove];
  const lod::GridMove m = lod::viewMoveToGridMove(viewer().camera().basis(), vm);
  const std::string what = std::string(lod::viewMoveName(vm)) + " = " + m.name();
  GridView& g = grid_;
  const glm::ivec3 from = nav.point();
  if (!g.storeWanted) g.fromPoint = from;
  const lod::MoveResult r = nav.apply(m);
  if (!r.moved) {
    g.note = what + " refused: " + r.reason;
    g.refused = true;
    return 0;
  }
  try {
    showGridBlock(nav.blockBox(nav.point()), true);
  } catch (...) {
    nav.moveTo(from);
    throw;
  }
  g.note = what + ": grid point " + nav.describe(nav.point());
  g.refused = false;
  return 1;
}

// The grid point and block go back to where they were before the enter or
// move that asked for the store's block.
void WebSession::gridStoreFailed() {
  GridView& g = grid_;
  if (!g.storeWanted || !g.nav) return;
  g.nav->moveTo(g.fromPoint);
  g.block = g.fromBlock;
  g.shownName = g.fromShownName;
  g.storeWanted = false;
  g.note = "the block could not be read; back at grid point " + g.nav->describe(g.fromPoint);
  g.refused = true;
}

void WebSession::gridStoreShown() {
  GridView& g = grid_;
  const StoreRegion& r = storeRegion_;
  if (!g.storeWanted || !g.block || !r.shown || r.box.begin != g.block->begin ||
      r.box.end != g.block->end) {
    throw InputError("grid view: the store's block has not been read");
  }
  g.storeWanted = false;
  g.shownName = viewer().volumeName();
  storeRegion_.gridBlock = true;
}

}  // namespace tessera::web
