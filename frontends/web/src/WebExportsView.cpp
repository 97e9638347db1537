// The C API of the 3D view (frontends/web/tessera.js, frontends/web/app.js): the session's
// start and end, volumes, frames, pointer input, the camera and the state.
// Each export marshals its arguments to the session (WebSession.h) and its
// results back: numbers, or JSON strings valid until the next call.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "WebExports.h"
#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/render/TechniqueRegistry.h"

using namespace tessera;
using web::guarded;
using web::viewerIfAny;

namespace tessera::web {

namespace {
std::string gLastError;
std::string gScratch;
}  // namespace

std::string& lastError() {
  return gLastError;
}

std::string& scratch() {
  return gScratch;
}

}  // namespace tessera::web

extern "C" {

// Creates the WebGL 2 (version 2) or WebGL 1 (version 1) context on the
// canvas named by `canvasSelector` ("#canvas"), the viewer on it (device
// profile webgl2 / webgl1) and the session; a session made before is ended.
EMSCRIPTEN_KEEPALIVE int tessera_init(const char* canvasSelector, int webglVersion) {
  return guarded([&] { web::startSession(canvasSelector, webglVersion); });
}

// After the browser restored the canvas's lost WebGL context
// (webglcontextrestored): the session made again on it, with the same
// volume and state (WebSession::recoverContext); 0 with the reason when
// something could not be brought back.
EMSCRIPTEN_KEEPALIVE int tessera_context_restored() {
  return guarded([&] { web::session().recoverContext(); });
}

// 1 once the browser has taken the canvas's WebGL context away, before its
// webglcontextlost event arrives (a frame drawn then only fails), until
// the context is restored; 0 otherwise.
EMSCRIPTEN_KEEPALIVE int tessera_context_lost() {
  const web::WebSession* s = web::sessionIfAny();
  return s && s->contextLost() ? 1 : 0;
}

// Ends the session: the viewer's GPU objects, the WebGL context and every
// volume, region, grid, zoom swap and store go.
EMSCRIPTEN_KEEPALIVE void tessera_dispose() {
  web::endSession();
}

EMSCRIPTEN_KEEPALIVE const char* tessera_last_error() {
  return web::lastError().c_str();
}

// "gen:shepp-logan:96" and the other procedural specs of `tessera render`.
EMSCRIPTEN_KEEPALIVE int tessera_load_generated(const char* spec) {
  return guarded([&] { web::session().loadGenerated(spec); });
}

// Files picked or dropped together: each is added (`bytes` malloc'ed by the
// page and owned from here on), then tessera_load_files reads the one that
// names the others (io/VolumeReader.h, volumeFileAmong) with the same io
// readers as the CLI, and drops them all.
EMSCRIPTEN_KEEPALIVE void tessera_add_file(const char* name, std::uint8_t* bytes, int size) {
  web::PickedFile f;
  f.name = name;
  f.bytes.reset(bytes);
  f.size = static_cast<std::size_t>(std::max(0, size));
  if (web::WebSession* s = web::sessionIfAny()) s->addFile(std::move(f));
}

EMSCRIPTEN_KEEPALIVE void tessera_clear_files() {
  if (web::WebSession* s = web::sessionIfAny()) s->clearFiles();
}

// The open time series (a dropped 4-D NIfTI; session/TimeSeries.h):
// {"count": N, "shown": t, "bricks": bool (a store's t axis over bricks),
// "playing": bool, "fps": f, "late": frames, "advances": n}, or
// {"count": 1} when the volume is not a series.
EMSCRIPTEN_KEEPALIVE const char* tessera_time_json() {
  web::WebSession* s = web::sessionIfAny();
  const session::TimeSeries* series = s ? s->rendering().series() : nullptr;
  if (!series) return web::jsonOut({{"count", 1}});
  session::Playback& p = s->rendering().playback();
  return web::jsonOut({{"count", series->count()},
                       {"shown", s->rendering().timePoint()},
                       {"bricks", s->rendering().streamedSeries() != nullptr},
                       {"playing", p.playing()},
                       {"fps", p.fps()},
                       {"late", p.lateFrames()},
                       {"advances", p.advances()}});
}

// Shows time point t if it has been read (1), else asks for it and reads
// one time point ahead (0: call again next frame); -1 with the reason for
// a t out of range or no series.
EMSCRIPTEN_KEEPALIVE int tessera_time_show(int t) {
  int shown = -1;
  const int ok = guarded([&] {
    session::Session& s = web::session().rendering();
    shown = s.showTimePoint(t) ? 1 : 0;
    if (!shown && s.series()) s.series()->pump();
  });
  return ok ? shown : -1;
}

// Starts (play 1) or pauses (0) playback at `fps` time points per second;
// 0 with the reason for a rate outside 0.1..120 or no series.
EMSCRIPTEN_KEEPALIVE int tessera_playback(int play, double fps, double nowMs) {
  return guarded([&] {
    session::Session& s = web::session().rendering();
    if (!s.series()) throw InputError("no time series is open (drop a 4-D NIfTI file)");
    s.playback().setFps(fps);
    if (play) {
      s.playback().play(nowMs);
    } else {
      s.playback().pause();
    }
  });
}

// Once per animation frame while playing: the time point to draw
// (Session::stepPlayback; it reads one time point ahead per call), -1 on
// error.
EMSCRIPTEN_KEEPALIVE int tessera_playback_step(double nowMs) {
  int shown = -1;
  const int ok = guarded([&] {
    web::WebSession& w = web::session();
    shown = w.rendering().stepPlayback(nowMs, w.storeTimeFinished());
  });
  return ok ? shown : -1;
}

EMSCRIPTEN_KEEPALIVE int tessera_load_files() {
  return guarded([&] { web::session().loadPickedFiles(); });
}

// Renders a frame on the canvas; returns its time in ms (-1 on error).
EMSCRIPTEN_KEEPALIVE double tessera_render(int width, int height) {
  double ms = -1.0;
  guarded([&] { ms = web::session().renderFrame(width, height); });
  return ms;
}

// Progressive full-quality frames (viewer::Viewer::progressive): the page
// calls tessera_refine once per animation frame while tessera_refining says
// a frame is pending; each call costs about `budgetMs`.
EMSCRIPTEN_KEEPALIVE void tessera_set_progressive(int on, double budgetMs) {
  viewer::Viewer* v = viewerIfAny();
  if (!v) return;
  v->progressive = on != 0;
  if (budgetMs > 0.0) v->frameBudgetMs = budgetMs;
}
EMSCRIPTEN_KEEPALIVE int tessera_refining() {
  const viewer::Viewer* v = viewerIfAny();
  return v && v->refining() ? 1 : 0;
}
EMSCRIPTEN_KEEPALIVE double tessera_refine() {
  double ms = -1.0;
  guarded([&] { ms = web::session().viewer().refine().ms; });
  return ms;
}

// Pointer input, y down; action 0 orbit, 1 pan. The page sends CSS pixels
// over a view of tessera_pointer_viewport's CSS size, so that a drag turns
// the view by the same angle per CSS pixel at every devicePixelRatio (each
// frame sets the viewport to its own pixels: call it before each pointer
// call).
EMSCRIPTEN_KEEPALIVE void tessera_pointer_viewport(double width, double height) {
  if (viewer::Viewer* v = viewerIfAny()) {
    v->controller().setViewport(static_cast<int>(std::lround(width)),
                                static_cast<int>(std::lround(height)));
  }
}
EMSCRIPTEN_KEEPALIVE void tessera_pointer_down(int id, double x, double y, int action) {
  if (viewer::Viewer* v = viewerIfAny()) {
    v->controller().pointerDown(
        id, {x, y}, action == 1 ? viewer::PointerAction::Pan : viewer::PointerAction::Orbit);
  }
}
EMSCRIPTEN_KEEPALIVE void tessera_pointer_move(int id, double x, double y) {
  if (viewer::Viewer* v = viewerIfAny()) v->controller().pointerMove(id, {x, y});
}
EMSCRIPTEN_KEEPALIVE void tessera_pointer_up(int id) {
  if (viewer::Viewer* v = viewerIfAny()) v->controller().pointerUp(id);
}
EMSCRIPTEN_KEEPALIVE void tessera_wheel(double notches) {
  if (viewer::Viewer* v = viewerIfAny()) v->controller().wheel(notches);
}
EMSCRIPTEN_KEEPALIVE int tessera_interacting() {
  viewer::Viewer* v = viewerIfAny();
  return v && v->controller().interacting() ? 1 : 0;
}

// Keeps the projection (tessera_set_projection).
EMSCRIPTEN_KEEPALIVE int tessera_set_camera(double azimuth, double elevation, double zoom) {
  return guarded([&] { web::session().setCamera(azimuth, elevation, zoom); });
}

// 1: orthographic (parallel rays; the view's half height is the framed
// radius / zoom), 0: perspective (the default).
EMSCRIPTEN_KEEPALIVE void tessera_set_projection(int orthographic) {
  if (viewer::Viewer* v = viewerIfAny()) {
    v->camera().projection = orthographic ? Projection::Orthographic : Projection::Perspective;
  }
}

// Everything the page shows about the state, as JSON (null before tessera_init).
EMSCRIPTEN_KEEPALIVE const char* tessera_state_json(int logHistogram) {
  nlohmann::json j;
  web::WebSession* session = web::sessionIfAny();
  if (!session) return web::jsonOut(j);
  viewer::Viewer& v = session->viewer();
  const gpu::DeviceCaps& caps = v.context().caps();
  j["webgl"] = session->webglVersion();
  j["api"] = gpu::apiLevelName(v.limits().api);
  j["renderer"] = caps.renderer;
  j["gl_version"] = caps.version;
  j["has_volume"] = v.hasVolume();
  j["description"] = v.description();
  j["techniques"] = render::TechniqueRegistry::global().names();
  j["technique"] = v.technique();
  j["labels"] = v.labelsOn();
  if (v.hasVolume()) {
    const glm::ivec3 d = v.volume().dims();
    j["name"] = v.volumeName();
    j["dims"] = {d.x, d.y, d.z};
    j["type"] = std::string(scalarTypeName(v.volume().type()));
    // Its geometry, as `tessera info --json` prints it.
    const Orientation orient = orientationOf(v.volume().direction());
    j["orientation"] = orient.code;
    j["orientation_text"] = orient.describe();
    j["geometry_source"] = v.volume().geometrySource();
    const glm::dmat4 a = v.volume().indexToWorld();
    j["affine"] = nlohmann::json::array();
    for (int row = 0; row < 4; ++row) {
      j["affine"].push_back({a[0][row], a[1][row], a[2][row], a[3][row]});
    }
    j["layout"] = v.storageName();
    j["plan_reason"] = v.plan().reason;
    j["range"] = {v.valueRange().min, v.valueRange().max};
    j["window"] = {v.window().min, v.window().max};
    j["histogram"] = v.tfEditor().histogramHeights(logHistogram != 0);
  }
  const EdgeLabels labels = v.orientationLabels();
  j["orientation_labels"] = {{"left", labels.left},
                             {"right", labels.right},
                             {"top", labels.top},
                             {"bottom", labels.bottom}};
  const Camera& c = v.camera();
  j["camera"] = {{"azimuth", c.azimuthDeg}, {"elevation", c.elevationDeg}, {"zoom", c.zoom}};
  const RenderSettings& rs = v.settings();
  j["sampling"] = {{"step", rs.stepVoxels},
                   {"preintegrate", rs.sampling.preintegrate},
                   {"adaptive", rs.sampling.adaptive},
                   {"tolerance", rs.sampling.tolerance},
                   {"max_multiplier", rs.sampling.maxMultiplier}};
  j["frame_ms"] = v.lastFrame().ms;
  j["refining"] = v.refining();
  j["render_size"] = {v.lastFrame().renderWidth, v.lastFrame().renderHeight};
  const viewer::TransferFunctionEditor::Selection& s = v.tfEditor().selection();
  j["selection"] = {{"channel", s.channel == viewer::TfChannel::Color ? 1 : 0}, {"index", s.index}};
  return web::jsonOut(j);
}

// The session's state (session::Session::state: settings, camera, TF,
// window, exploration) as versioned JSON, what `tessera render --state` and
// `tessera view --state` read; "null" before tessera_init.
EMSCRIPTEN_KEEPALIVE const char* tessera_session_state() {
  web::WebSession* s = web::sessionIfAny();
  if (!s) return web::jsonOut(nullptr);
  nlohmann::json j;
  if (!guarded([&] { j = s->rendering().state(); })) return web::jsonOut(nullptr);
  return web::jsonOut(j);
}

// Restores a state of tessera_session_state (or of the CLI or the desktop
// viewer) on the volume loaded now: the look, the camera and, for a file,
// the crosshair, picked region, grid and the region or block it showed.
EMSCRIPTEN_KEEPALIVE int tessera_session_restore(const char* json) {
  return guarded([&] { web::session().restoreState(json); });
}

// The canvas's pixels (RGBA, top row first), for tests and "save image";
// valid until the next call (null before tessera_init).
EMSCRIPTEN_KEEPALIVE const std::uint8_t* tessera_read_pixels(int width, int height) {
  web::WebSession* s = web::sessionIfAny();
  return s ? s->readPixels(width, height) : nullptr;
}

}  // extern "C"
