// The C API of the overlay (frontends/web/overlay-panel.js): a second
// volume over the first, its look, and the crosshair's probe. Each export
// marshals its arguments to WebOverlay.h and its results back.
#include <cmath>
#include <string>

#include "WebExports.h"
#include "WebOverlay.h"

using namespace tessera;
using web::guarded;

namespace {

// The page's controls as the session's options: a window when lo < hi
// (NaN otherwise: the overlay's value range).
session::OverlayOptions optionsOf(int labels, const char* tableText, const char* tableName,
                                  const char* tf, double alpha, double lo, double hi) {
  session::OverlayOptions o;
  o.labels = labels != 0;
  o.labelTableText = tableText ? tableText : "";
  o.labelTableName = tableName ? tableName : "";
  if (tf && *tf) o.tf = tf;
  o.opacity = alpha;
  if (std::isfinite(lo) && std::isfinite(hi)) o.window = ValueRange{lo, hi};
  return o;
}

}  // namespace

extern "C" {

// Opens the files handed over with tessera_add_file as the overlay over the
// open volume (labels != 0: a label volume, with the table's text, or ""
// for the default palette; otherwise the colour map `tf`); 0 with the reason
// (on WebGL 1: it needs WebGL 2).
EMSCRIPTEN_KEEPALIVE int tessera_overlay_open(int labels, const char* tableText,
                                              const char* tableName, const char* tf, double alpha,
                                              double lo, double hi) {
  return guarded([&] {
    web::openPickedOverlay(web::session(),
                           optionsOf(labels, tableText, tableName, tf, alpha, lo, hi));
  });
}

// The open overlay with another look (same arguments).
EMSCRIPTEN_KEEPALIVE int tessera_overlay_restyle(int labels, const char* tableText,
                                                 const char* tableName, const char* tf,
                                                 double alpha, double lo, double hi) {
  return guarded([&] {
    web::restyleOverlay(web::session(), optionsOf(labels, tableText, tableName, tf, alpha, lo, hi));
  });
}

EMSCRIPTEN_KEEPALIVE void tessera_overlay_clear() {
  guarded([&] { web::session().rendering().clearOverlay(); });
}

// JSON (WebOverlay.h overlayJson); {"open": false} without one.
EMSCRIPTEN_KEEPALIVE const char* tessera_overlay_json() {
  nlohmann::json j = {{"open", false}};
  guarded([&] { j = web::overlayJson(web::session()); });
  return web::jsonOut(j);
}

// The crosshair's probe at voxel (x, y, z) of the slice views: JSON
// (session::probeJson), null on error.
EMSCRIPTEN_KEEPALIVE const char* tessera_probe_json(int x, int y, int z) {
  nlohmann::json j = nullptr;
  guarded([&] { j = web::probeAtVoxel(web::session(), {x, y, z}); });
  return web::jsonOut(j);
}

// The slice views' voxel nearest a world position (RAS+ mm): [i, j, k], or
// null without a volume.
EMSCRIPTEN_KEEPALIVE const char* tessera_voxel_at_world(double x, double y, double z) {
  nlohmann::json j = nullptr;
  guarded([&] {
    const glm::ivec3 v = web::voxelAtWorld(web::session(), {x, y, z});
    j = {v.x, v.y, v.z};
  });
  return web::jsonOut(j);
}

}  // extern "C"
