// The C API of OME-Zarr stores over fetch() (frontends/web/zarr-url.js drives it): the
// page fetches the keys a step wants and hands them over. Each export
// marshals its arguments to the session's store (WebSessionStore.cpp,
// ZarrStoreView.h) and its results back.
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "WebExports.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/Draw.h"

using namespace tessera;
using web::guarded;

namespace {

// The open store, or null (no session, or no store): the calls that hand
// fetched keys over do nothing then.
web::ZarrStoreView* storeIfAny() {
  web::WebSession* s = web::sessionIfAny();
  return s ? s->store() : nullptr;
}

lod::VoxelBox boxOf(int x0, int x1, int y0, int y1, int z0, int z1) {
  return {{x0, y0, z0}, {x1, y1, z1}};
}

// `errorQueries`: the GL error queries the call made (gpu::errorQueries).
std::string frameJson(const web::StoreFrame& f, web::ZarrStoreView& z, std::uint64_t errorQueries) {
  const lod::StreamerStats st = z.bricks().streamerStats();
  const web::FetchStats fetched = z.storage().stats();
  nlohmann::json j;
  j["ms"] = f.ms;
  j["stream_ms"] = f.streamMs;
  j["update_ms"] = f.updateMs;
  j["upload_wait_ms"] = f.uploadWaitMs;
  j["tables_ms"] = f.tablesMs;
  j["preview_ms"] = f.previewMs;
  j["setup_ms"] = f.setupMs;
  j["strip_rows"] = f.stripRows;
  j["shown"] = f.shown;
  j["pending"] = f.pending;
  j["streamed"] = f.streamed;
  j["render_size"] = {f.renderWidth, f.renderHeight};
  j["preview_size"] = {f.previewWidth, f.previewHeight};
  j["complete"] = f.bricks.complete;
  j["wanted"] = f.bricks.wanted;
  j["missing"] = f.bricks.missing;
  j["failing"] = f.bricks.failing;
  j["uploaded"] = f.bricks.uploaded;
  j["uploaded_now"] = f.uploadedNow;
  j["tables_rebuilt"] = f.tablesRebuilt;
  j["error_queries"] = errorQueries;
  j["limited_by_budget"] = f.bricks.limitedByBudget;
  j["wanted_per_level"] = f.bricks.wantedPerLevel;
  j["cells_per_level"] = f.bricks.cellsPerLevel;  // last: transparent cells
  j["bricks_read"] = st.bricksRead;
  j["read_errors"] = st.readErrors;
  j["last_error"] = st.lastError;
  j["fetched_keys"] = fetched.keys;
  j["fetched_bytes"] = fetched.bytes;
  j["fetch_failures"] = fetched.failed;
  j["held_bytes"] = fetched.heldBytes;
  return j.dump();
}

}  // namespace

extern "C" {

// The chunk cache of the stores opened from now on, in MiB (the page's
// ?zarrcache=MiB; default 48): 0 with the reason outside 1/16..48.
EMSCRIPTEN_KEEPALIVE int tessera_zarr_set_cache_mib(double mib) {
  return guarded([&] { web::session().setStoreCacheBytes(mib * 1048576.0); });
}

// The share of the frame budget a store's strips take (the page's
// ?stripshare=; default 0.25): 0 with the reason outside 0.05..1.
EMSCRIPTEN_KEEPALIVE int tessera_zarr_set_strip_share(double share) {
  return guarded([&] { web::session().setStoreStripShare(share); });
}

// Starts opening the store at `url` (its root, e.g. http://host/ch2.ome.zarr).
EMSCRIPTEN_KEEPALIVE int tessera_zarr_begin(const char* url) {
  return guarded([&] { web::session().beginStore(url); });
}

// One step of opening: 1 open (the coarsest level is on the GPU), 0 keys
// are wanted (tessera_zarr_wanted), -1 failed (tessera_last_error).
EMSCRIPTEN_KEEPALIVE int tessera_zarr_open_step() {
  int state = -1;
  guarded([&] { state = web::session().storeOpenStep() ? 1 : 0; });
  return state;
}

// The keys wanted since the last call, most urgent first, as a JSON array.
EMSCRIPTEN_KEEPALIVE const char* tessera_zarr_wanted() {
  nlohmann::json keys = nlohmann::json::array();
  if (web::ZarrStoreView* z = storeIfAny()) {
    for (const std::string& k : z->storage().takeWanted()) keys.push_back(k);
  }
  return web::jsonOut(keys);
}

// 1 when the 3D view shows a region or grid block read from the open store
// (the viewer's frames, not the store's): after a context loss the store
// opened again shows the one it showed (WebSession::storeOpenStep).
EMSCRIPTEN_KEEPALIVE int tessera_zarr_region_shown() {
  web::WebSession* s = web::sessionIfAny();
  return s && s->storeRegionShown() ? 1 : 0;
}

// 1 when the key has arrived (or is known missing, or failed moments ago):
// the page does not fetch it again when it is listed twice.
EMSCRIPTEN_KEEPALIVE int tessera_zarr_holds(const char* key) {
  web::ZarrStoreView* z = storeIfAny();
  return z && z->storage().holds(key) ? 1 : 0;
}

// A fetched key: its bytes (malloc'ed by the page, freed here), a 404, or
// the page's error after its retries (naming the URL).
EMSCRIPTEN_KEEPALIVE void tessera_zarr_put(const char* key, std::uint8_t* bytes, int size) {
  const std::unique_ptr<std::uint8_t, decltype(&std::free)> owned(bytes, &std::free);
  web::ZarrStoreView* z = storeIfAny();
  if (!z) return;
  const auto* b = reinterpret_cast<const std::byte*>(bytes);
  z->storage().put(key, std::vector<std::byte>(b, b + std::max(0, size)));
}
// A fetched range of a key (its key from tessera_zarr_wanted, "KEY#bytes=A-B"):
// its bytes (freed here), the whole value's size, and 1 when the page
// decoded them (a shard's inner chunk of a compressor it decodes).
EMSCRIPTEN_KEEPALIVE void tessera_zarr_put_range(const char* key, std::uint8_t* bytes, int size,
                                                 double total, int decoded) {
  const std::unique_ptr<std::uint8_t, decltype(&std::free)> owned(bytes, &std::free);
  web::ZarrStoreView* z = storeIfAny();
  if (!z) return;
  const auto* b = reinterpret_cast<const std::byte*>(bytes);
  z->storage().putRange(key, std::vector<std::byte>(b, b + std::max(0, size)),
                        static_cast<std::uint64_t>(std::max(0.0, total)), decoded != 0);
}
EMSCRIPTEN_KEEPALIVE void tessera_zarr_put_missing(const char* key) {
  if (web::ZarrStoreView* z = storeIfAny()) z->storage().putMissing(key);
}
EMSCRIPTEN_KEEPALIVE void tessera_zarr_put_failed(const char* key, const char* message) {
  if (web::ZarrStoreView* z = storeIfAny()) z->storage().putFailed(key, message);
}

// The page decodes chunks of this compressor ("blosc", "zstd") itself
// (numcodecs, frontends/web/zarr-url.js) before it hands them over.
EMSCRIPTEN_KEEPALIVE int tessera_zarr_page_decodes(const char* compressor) {
  return guarded(
      [&] { web::session().theStore().storage().setPageDecodes(parseZarrCompressor(compressor)); });
}

// A frame of the open store on the canvas, with the picked region (red) and
// the grid view's last block (cyan) composed by depth, paced as the
// viewer's progressive frames (tessera_set_progressive): when the whole
// frame costs more than the budget, a preview now if `viewChanged` (else the
// canvas keeps its image), and the full frame through tessera_zarr_refine.
// JSON with the bricks' state ("complete", "wanted", "missing", "failing",
// "uploaded", cells per level; "uploaded_now": by this call), "shown" (drew
// on the canvas), "pending" (the full frame is still to come) and
// "error_queries" (the GL error queries it made, each a wait for the GPU
// process), or "" on error (tessera_last_error).
// `inputWaitedMs`: how long the input event it answers has waited since its
// time stamp (negative: it answers none); see StorePace::inputWaitedMs.
EMSCRIPTEN_KEEPALIVE const char* tessera_zarr_frame(int width, int height, int viewChanged,
                                                    double inputWaitedMs) {
  web::scratch().clear();
  guarded([&] {
    web::WebSession& s = web::session();
    const std::uint64_t asked = gpu::errorQueries();
    const web::StoreFrame f = s.storeFrame(width, height, viewChanged != 0, inputWaitedMs);
    web::scratch() = frameJson(f, s.theStore(), gpu::errorQueries() - asked);
  });
  return web::scratch().c_str();
}

// 1 while a store frame is pending (tessera_zarr_refine draws it).
EMSCRIPTEN_KEEPALIVE int tessera_zarr_refining() {
  const web::ZarrStoreView* z = storeIfAny();
  return z && z->refining() ? 1 : 0;
}

// About a budget of the pending frame: streaming what arrived, then a strip
// of its ray march; the same JSON as tessera_zarr_frame ("shown" once the
// last strip is drawn and the frame is on the canvas), "" on error.
EMSCRIPTEN_KEEPALIVE const char* tessera_zarr_refine() {
  web::scratch().clear();
  guarded([&] {
    web::WebSession& s = web::session();
    const std::uint64_t asked = gpu::errorQueries();
    const web::StoreFrame f = s.storeRefine();
    web::scratch() = frameJson(f, s.theStore(), gpu::errorQueries() - asked);
  });
  return web::scratch().c_str();
}

// The open store: its description, levels and the bricks layout's plan.
EMSCRIPTEN_KEEPALIVE const char* tessera_zarr_info() {
  web::scratch().clear();
  guarded([&] {
    const web::ZarrStoreView& z = web::session().theStore();
    nlohmann::json j;
    j["url"] = z.store().storage().describe();
    j["description"] = z.store().describe();
    j["open"] = z.isOpen();
    j["levels"] = nlohmann::json::array();
    for (int l = 0; l < z.store().levelCount(); ++l) {
      const ZarrLevel& lv = z.store().level(l);
      j["levels"].push_back({{"path", lv.path},
                             {"dims", {lv.dims.x, lv.dims.y, lv.dims.z}},
                             {"chunk", {lv.chunk.x, lv.chunk.y, lv.chunk.z}},
                             {"compressor", lv.array.compressorText}});
    }
    if (z.isOpen()) {
      j["layout_reason"] = z.bricks().plan().reason;
      j["brick_size"] = z.bricks().grid().brickSize();
      j["slots"] = z.bricks().slotCount();
    }
    j["notes"] = z.store().notes();
    web::scratch() = j.dump();
  });
  return web::scratch().c_str();
}

// The bread-slice region of a store: voxels [x0,x1) x [y0,y1) x [z0,z1) of
// level 0 of the time point shown (its t axis played), read with bounded
// reads. 1 when every level-0 chunk of the box has arrived, 0 when some are wanted
// (tessera_zarr_wanted lists them: the page fetches them and asks again), -1 on error
// (tessera_last_error).
EMSCRIPTEN_KEEPALIVE int tessera_zarr_region_prefetch(int x0, int x1, int y0, int y1, int z0,
                                                      int z1) {
  int state = -1;
  guarded(
      [&] { state = web::session().storeRegionPrefetch(boxOf(x0, x1, y0, y1, z0, z1)) ? 1 : 0; });
  return state;
}

// Reads the box (its chunks fetched: tessera_zarr_region_prefetch) at level
// 0 of the time point shown and makes it the viewer's volume, placed and
// windowed as in the store (what `tessera render STORE --time T --region`
// reads); the page then draws the viewer instead of the store until it goes
// back to the store's overview. Playing on, the session reads it again from
// each time point (Session::showTimePoint).
EMSCRIPTEN_KEEPALIVE int tessera_zarr_region_show(int x0, int x1, int y0, int y1, int z0, int z1) {
  return guarded([&] { web::session().showStoreRegion(boxOf(x0, x1, y0, y1, z0, z1)); });
}

// Back to the store's overview from its region (the page draws the store
// again; the region stays known, for its outline in the slice views).
EMSCRIPTEN_KEEPALIVE void tessera_zarr_region_overview() {
  if (web::WebSession* s = web::sessionIfAny()) s->storeRegionOverview();
}

// Closes the store (the viewer core's volume shows again).
EMSCRIPTEN_KEEPALIVE void tessera_zarr_close() {
  if (web::WebSession* s = web::sessionIfAny()) s->closeStore();
}

}  // extern "C"
