// The C API of exploring a volume (frontends/web/slices.js, frontends/web/grid.js): the slice
// views, the bread-slice region, the boxes marked in the 3D view, the grid
// view and the zoom-driven level swap. Each export marshals its arguments to
// the session (WebSession.h, WebSessionExplore.cpp, WebSessionZoom.cpp) and
// its results back as numbers or JSON strings valid until the next call.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "WebExports.h"
#include "tessera/core/Error.h"

using namespace tessera;
using web::boxJson;
using web::guarded;

namespace {

lod::VoxelBox boxOf(int x0, int x1, int y0, int y1, int z0, int z1) {
  return {{x0, y0, z0}, {x1, y1, z1}};
}

nlohmann::json matrixJson(const glm::dmat4& m) {
  nlohmann::json j = nlohmann::json::array();
  for (int col = 0; col < 4; ++col) {
    for (int row = 0; row < 4; ++row) j.push_back(m[col][row]);
  }
  return j;
}

}  // namespace

extern "C" {

// Slice `index` along index axis `axis` (0 x, 1 y, 2 z) of the slice views'
// volume through the viewer's window, nearest voxel at voxel centres, grey
// or (colour != 0) in the colours of the viewer's TF (`tessera slice
// --tf`): JSON with the image (`pixels`: RGBA, top row first, image_width x
// image_height, valid until the next call for this axis), its frame (plane,
// the index axes of columns and rows and whether they run reversed; width x
// height pixels of pixel_mm in the volume's voxel space: the image is shown
// stretched to that) and the patient directions of its edges; "" on error
// (tessera_last_error).
//
// An OME-Zarr store's slice (indices of level 0) is read at the finest level
// whose slice has at most `maxPixels` pixels (the panel's: finer would not
// show; <= 0: level 0); until that slab's chunks have arrived the coarsest
// level stands in and `pending` is true: the page fetches the chunks
// (tessera_zarr_wanted) and asks again; `note` names a chunk that keeps
// failing.
EMSCRIPTEN_KEEPALIVE const char* tessera_slice(int axis, int index, int colour, double maxPixels) {
  web::scratch().clear();
  guarded([&] {
    web::WebSession& s = web::session();
    const web::SliceResult r = s.slice(axis, index, colour != 0, maxPixels);
    const SliceFrame& f = r.frame;
    nlohmann::json j;
    j["axis"] = axis;
    j["index"] = index;
    j["count"] = r.count;
    j["plane"] = f.plane;
    j["edges"] = {{"left", f.left}, {"right", f.right}, {"top", f.top}, {"bottom", f.bottom}};
    // Letters only where the file says how the patient lay (as the 3D view).
    j["oriented"] = r.oriented;
    j["col_axis"] = f.colAxis;
    j["row_axis"] = f.rowAxis;
    j["col_reversed"] = f.colReversed;
    j["row_reversed"] = f.rowReversed;
    j["width"] = r.raster.width;
    j["height"] = r.raster.height;
    j["pixel_mm"] = r.raster.pixelMm;
    j["image_width"] = r.image->width();
    j["image_height"] = r.image->height();
    j["level"] = r.level;
    j["pending"] = r.pending;
    j["note"] = r.note;
    j["tf_revision"] = s.viewer().tfEditor().revision();
    j["pixels"] = reinterpret_cast<std::uintptr_t>(r.image->rgba().data());
    web::scratch() = j.dump();
  });
  return web::scratch().c_str();
}

// Raw value of voxel (x, y, z) of the slice views' volume (NaN outside it;
// a store's level-0 voxel once its chunk has arrived, the coarsest level's
// otherwise).
EMSCRIPTEN_KEEPALIVE double tessera_voxel_value(int x, int y, int z) {
  double value = std::nan("");
  guarded([&] { value = web::session().voxelValue(x, y, z); });
  return value;
}

// The overview volume and the region: JSON {has_volume, tf_revision, name,
// dims, spacing, index_to_world (3 rows of 4), region: null or {begin, end}, showing_region,
// region_side, region_side_reason}.
EMSCRIPTEN_KEEPALIVE const char* tessera_explore_json() {
  nlohmann::json j;
  j["has_volume"] = false;
  guarded([&] {
    web::WebSession* s = web::sessionIfAny();
    const Volume* store = s ? s->storeOverview() : nullptr;
    if (!s || (!s->viewer().hasVolume() && !store)) return;
    const bool inRegion = s->regionShown();
    const Volume& volume = s->sliceShape();
    const glm::ivec3 d = volume.dims();
    const glm::dvec3 sp = volume.spacing();
    j["has_volume"] = true;
    j["tf_revision"] = s->viewer().tfEditor().revision();
    j["labels"] = s->viewer().labelsOn();  // slices in the label colours
    j["name"] = s->overviewName();
    j["dims"] = {d.x, d.y, d.z};
    j["spacing"] = {sp.x, sp.y, sp.z};
    // Voxel index -> RAS+ millimetres (rows), for the crosshair's position.
    const glm::dmat4 a = volume.indexToWorld();
    j["index_to_world"] = nlohmann::json::array();
    for (int row = 0; row < 3; ++row) {
      j["index_to_world"].push_back({a[0][row], a[1][row], a[2][row], a[3][row]});
    }
    j["showing_region"] = inRegion;
    // The time point the 3D view shows (a series played; -1: none), which
    // the slices show too (WebSession::slice): a new one redraws them.
    const session::Session& r = s->rendering();
    j["time"] = r.series() ? r.timePoint() : -1;
    // A store: the slices, crosshair and regions are in level-0 voxels (these
    // dims), the slices read at the level their panel shows (tessera_slice);
    // its region is the box read at level 0 (also as region_level0).
    j["store"] = store != nullptr;
    j["region"] = inRegion ? boxJson(*s->exploration().shown()) : nlohmann::json(nullptr);
    if (store && inRegion) j["region_level0"] = j["region"];
    auto [side, why] = s->defaultRegionSide(volume);
    j["region_side"] = side;
    j["region_side_reason"] = why;
  });
  return web::jsonOut(j);
}

// Shows voxels [x0,x1) x [y0,y1) x [z0,z1) of the overview volume, at its
// native resolution, as the 3D view (ends past the volume are clamped; an
// empty box or one that starts outside is an error). The window, the TF and
// the overview stay; tessera_region_overview goes back.
EMSCRIPTEN_KEEPALIVE int tessera_region_show(int x0, int x1, int y0, int y1, int z0, int z1) {
  return guarded([&] { web::session().showRegion(boxOf(x0, x1, y0, y1, z0, z1)); });
}

// Back to the overview (with its camera and the current window); the
// region stays known to the page, which draws it as a highlighted box.
EMSCRIPTEN_KEEPALIVE int tessera_region_overview() {
  return guarded([&] { web::session().returnToOverview(); });
}

// Marks box [x0,x1) x [y0,y1) x [z0,z1) of the overview in slot 0 (the
// region, red) or 1 (the grid block, cyan) for the next frames, drawn as
// lines composed with the volume by depth; an empty box clears the slot.
// Clamped to the overview.
EMSCRIPTEN_KEEPALIVE int tessera_set_mark_box(int slot, int x0, int x1, int y0, int y1, int z0,
                                              int z1) {
  return guarded([&] { web::session().setMarkBox(slot, boxOf(x0, x1, y0, y1, z0, z1)); });
}

// How the 3D view projects the overview's voxel coordinates onto a
// width x height canvas: JSON {mvp (column-major 4x4, model frame to clip
// space, as the viewer's overlay lines), spacing, offset}: a point at
// continuous voxel coordinates p (voxel i spans [i, i+1]) of the overview
// lies at model point p * spacing + offset of the volume the view shows.
EMSCRIPTEN_KEEPALIVE const char* tessera_projection_json(int width, int height) {
  nlohmann::json j;
  guarded([&] {
    const std::optional<web::VoxelProjection> p = web::session().projection(width, height);
    if (!p) return;
    j["mvp"] = matrixJson(p->mvp);
    j["spacing"] = {p->spacing.x, p->spacing.y, p->spacing.z};
    j["offset"] = {p->offset.x, p->offset.y, p->offset.z};
  });
  return web::jsonOut(j);
}

// ---- the grid view (Schultz 2016 §7.3; lod::GridNavigator): the 2x2x2
// block of cells around the current grid point is shown as the 3D view the
// way the region is, so tessera_region_overview returns from either.

// Enters the grid view (or starts it again) at the grid point nearest the
// centre of voxel (x, y, z) of the overview (the crosshair), with cubic
// cells of `cellSide` voxels (0: the default for the profile, -1: as
// before), and shows that point's block.
EMSCRIPTEN_KEEPALIVE int tessera_grid_enter(int cellSide, int x, int y, int z) {
  return guarded([&] { web::session().gridEnter(cellSide, {x, y, z}); });
}

// One of the six moves relative to the view (0 forward, 1 back, 2 left,
// 3 right, 4 up, 5 down; lod::viewMoveToGridMove with the 3D view's camera):
// 1 moved (the new block is shown), 0 refused at the grid's boundary (the
// reason in tessera_grid_json's note; nothing changes), -1 error.
EMSCRIPTEN_KEEPALIVE int tessera_grid_move(int viewMove) {
  int result = -1;
  guarded([&] { result = web::session().gridMove(viewMove); });
  return result;
}

// The grid view: JSON {has_volume, active (its block is the 3D view),
// cell_size, cells, point, point_class, describe, block (the last block
// shown, the slices' voxels, end exclusive; null before the first),
// block_text, moves (per view move: its name, the grid move, legal and why
// not), note, refused, default_cell, store, store_wanted}.
EMSCRIPTEN_KEEPALIVE const char* tessera_grid_json() {
  nlohmann::json j;
  j["has_volume"] = false;
  guarded([&] {
    web::WebSession* s = web::sessionIfAny();
    if (!s || (!s->viewer().hasVolume() && !s->storeOverview())) return;
    if (s->storeOverview() && !s->theStore().isOpen()) return;
    const Volume& volume = s->sliceShape();
    const tessera::session::Exploration& e = s->exploration();
    const lod::GridNavigator& nav = e.explorer().grid();
    const bool wanted = s->gridStoreWanted();
    // The block shown last, or the one a store is fetching.
    const std::optional<lod::VoxelBox> block = wanted ? e.pending()->box : e.gridBlock();
    const glm::ivec3 cs = nav.cellSize(), cells = nav.cells(), p = nav.point();
    j["has_volume"] = true;
    j["active"] = s->gridShown();
    j["cell_size"] = {cs.x, cs.y, cs.z};
    j["cells"] = {cells.x, cells.y, cells.z};
    j["point"] = {p.x, p.y, p.z};
    j["point_class"] = lod::gridPointClassName(nav.pointClass());
    j["describe"] = nav.describe(p);
    if (block) {
      j["block"] = boxJson(*block);
      j["block_text"] = tessera::session::boxText(*block);
    } else {
      j["block"] = nullptr;
    }
    j["moves"] = nlohmann::json::array();
    const glm::dmat3 basis = s->viewer().camera().basis();
    for (const lod::ViewMove vm : web::kViewMoves) {
      const lod::GridMove m = lod::viewMoveToGridMove(basis, vm);
      const lod::MoveResult r = nav.check(p, m);
      j["moves"].push_back({{"view", lod::viewMoveName(vm)},
                            {"move", m.name()},
                            {"legal", r.moved},
                            {"reason", r.reason}});
    }
    j["note"] = e.note();
    j["refused"] = e.refused();
    j["default_cell"] = s->defaultGrid(volume).cellSize().x;
    // A store: the block (level-0 voxels) the page is to fetch and show
    // (tessera_zarr_region_prefetch / _show, then tessera_grid_store_shown).
    j["store"] = s->storeOverview() != nullptr;
    j["store_wanted"] = wanted;
  });
  return web::jsonOut(j);
}

// A store's block could not be read (its chunks kept failing): the grid
// point and block go back to where they were before the enter or move that
// asked for it (the 3D view still shows that block, or the store), with a
// note saying so.
EMSCRIPTEN_KEEPALIVE int tessera_grid_store_failed() {
  return guarded([&] { web::session().gridStoreFailed(); });
}

// A store's block (tessera_grid_json's block) has been read and shown by
// tessera_zarr_region_show: it is now the grid view's.
EMSCRIPTEN_KEEPALIVE int tessera_grid_store_shown() {
  return guarded([&] { web::session().gridStoreShown(); });
}

// ---- the zoom-driven level swap (viewer::ZoomSwap; WebSessionZoom.cpp)

// on = 1: the zoom drives the 3D view of the loaded file (stages for a view
// `viewPixels` high; `overviewVoxels` > 0 replaces the profile's overview
// budget and `blockVoxels` > 0 its native block budget, e.g. to see all
// three stages on a small volume). on = 0: the whole volume again, with the
// camera kept. 0 on error (tessera_last_error), nothing changed.
EMSCRIPTEN_KEEPALIVE int tessera_zoom_swap(int on, int viewPixels, double overviewVoxels,
                                           double blockVoxels) {
  return guarded([&] {
    if (on == 0) {
      web::session().zoomStop();
    } else {
      web::session().zoomStart(viewPixels, overviewVoxels, blockVoxels);
    }
  });
}

// The zoom swap: JSON {active, name, stages: [{name, level, native,
// enter_zoom}], shown_stage, shown (the viewer's volume), zoom (in the whole
// volume's terms), fading, mix, target, block (level-0 voxels, end
// exclusive, or null), voxels_read (by the swaps: bounded reads),
// whole_voxels, medium_level}.
EMSCRIPTEN_KEEPALIVE const char* tessera_zoom_json() {
  nlohmann::json j;
  j["active"] = false;
  guarded([&] {
    web::WebSession* s = web::sessionIfAny();
    if (!s || !s->zoomActive()) return;
    const viewer::ZoomSwap& zs = *s->zoomSwap();
    viewer::Viewer& v = s->viewer();
    j["active"] = true;
    j["name"] = s->zoomName();
    j["stages"] = nlohmann::json::array();
    for (const lod::ZoomStage& st : zs.policy().stages()) {
      j["stages"].push_back({{"name", st.name},
                             {"level", st.level},
                             {"native", st.subVolume},
                             {"enter_zoom", st.enterZoom}});
    }
    j["shown_stage"] = zs.shownStage();
    j["shown"] = v.volumeName();
    j["zoom"] = zs.overviewZoom(v.camera());
    j["fading"] = zs.fading();
    j["mix"] = zs.policy().frame().mix;
    j["target"] = zs.policy().stageFor(std::max(0, zs.shownStage()), zs.overviewZoom(v.camera()));
    j["block"] = zs.shownBox() ? boxJson(*zs.shownBox()) : nlohmann::json(nullptr);
    j["voxels_read"] = zs.voxelsRead();
    j["whole_voxels"] = s->zoomOverview()->voxelCount();
    j["medium_level"] = s->zoomMediumLevel();
  });
  return web::jsonOut(j);
}

}  // extern "C"
