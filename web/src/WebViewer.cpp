// The web front end's C++ half: a WebGL context on the page's canvas, the
// shared viewer core on it, and a small C API the page's JavaScript calls
// (web/app.js). Every call that can fail returns 0 and leaves the message in
// tessera_last_error(); the viewer keeps its previous state.
#include <emscripten/emscripten.h>
#include <emscripten/html5.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/Draw.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/io/ByteSource.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/viewer/Viewer.h"

using namespace tessera;

namespace {

// A file the page handed over (malloc'ed by it, freed here).
struct PickedFile {
  std::string name;
  std::unique_ptr<std::uint8_t, decltype(&std::free)> bytes{nullptr, &std::free};
  std::size_t size = 0;
};

struct WebApp {
  EMSCRIPTEN_WEBGL_CONTEXT_HANDLE handle = 0;
  int webglVersion = 0;
  std::unique_ptr<gpu::GlContext> context;
  std::unique_ptr<viewer::Viewer> viewer;
  std::vector<PickedFile> picked;
};

WebApp& app() {
  static WebApp a;
  return a;
}

std::string& lastError() {
  static std::string e;
  return e;
}

std::string& scratch() {
  static std::string s;
  return s;
}

// Runs f; on an exception keeps its message and returns 0.
template <class F>
int guarded(F&& f) {
  try {
    f();
    lastError().clear();
    return 1;
  } catch (const std::exception& e) {
    lastError() = e.what();
    return 0;
  }
}

viewer::Viewer& theViewer() {
  if (!app().viewer) throw GpuError("the viewer has no WebGL context yet");
  return *app().viewer;
}

glm::dvec3 toRgb(double r, double g, double b) {
  return {r, g, b};
}

}  // namespace

extern "C" {

// Creates the WebGL 2 (version 2) or WebGL 1 (version 1) context on
// #canvas and the viewer (device profile webgl2 / webgl1).
EMSCRIPTEN_KEEPALIVE int tessera_init(int webglVersion) {
  return guarded([&] {
    EmscriptenWebGLContextAttributes attrs;
    emscripten_webgl_init_context_attributes(&attrs);
    attrs.majorVersion = webglVersion >= 2 ? 2 : 1;
    attrs.minorVersion = 0;
    attrs.alpha = false;
    attrs.depth = false;
    attrs.stencil = false;
    attrs.antialias = false;
    // The page and its tests read the canvas after the frame.
    attrs.preserveDrawingBuffer = true;
    attrs.enableExtensionsByDefault = true;
    const EMSCRIPTEN_WEBGL_CONTEXT_HANDLE h = emscripten_webgl_create_context("#canvas", &attrs);
    if (h <= 0) {
      throw GpuError("this browser offers no WebGL " + std::to_string(attrs.majorVersion) +
                     " context");
    }
    emscripten_webgl_make_context_current(h);
    const gpu::ApiLevel api = attrs.majorVersion == 2 ? gpu::ApiLevel::Gles3 : gpu::ApiLevel::Gles2;
    const std::string profile = attrs.majorVersion == 2 ? "webgl2" : "webgl1";
    app().context = gpu::GlContext::adoptCurrent(api, profile);
    app().viewer =
        std::make_unique<viewer::Viewer>(*app().context, gpu::DeviceProfile::find(profile));
    app().handle = h;
    app().webglVersion = attrs.majorVersion;
  });
}

EMSCRIPTEN_KEEPALIVE const char* tessera_last_error() {
  return lastError().c_str();
}

// "gen:shepp-logan:96" and the other procedural specs of `tessera render`.
EMSCRIPTEN_KEEPALIVE int tessera_load_generated(const char* spec) {
  return guarded([&] { theViewer().setVolume(makeProcedural(spec), spec); });
}

// Files picked or dropped together: each is added (`bytes` malloc'ed by the
// page and owned from here on), then tessera_load_files reads the one that
// names the others (io/VolumeReader.h, volumeFileAmong) with the same io
// readers as the CLI, and drops them all.
EMSCRIPTEN_KEEPALIVE void tessera_add_file(const char* name, std::uint8_t* bytes, int size) {
  PickedFile f;
  f.name = name;
  f.bytes.reset(bytes);
  f.size = static_cast<std::size_t>(size);
  app().picked.push_back(std::move(f));
}

EMSCRIPTEN_KEEPALIVE void tessera_clear_files() {
  app().picked.clear();
}

EMSCRIPTEN_KEEPALIVE int tessera_load_files() {
  const int ok = guarded([&] {
    MemoryFiles files;
    for (const PickedFile& f : app().picked) {
      files.add(f.name, std::span<const std::byte>(
                            reinterpret_cast<const std::byte*>(f.bytes.get()), f.size));
    }
    const std::string name = volumeFileAmong(files.names());
    theViewer().setVolume(readVolume(*files.open(name), files), name);
  });
  app().picked.clear();
  return ok;
}

// Renders a frame on the canvas; returns its time in ms (-1 on error).
EMSCRIPTEN_KEEPALIVE double tessera_render(int width, int height) {
  double ms = -1.0;
  guarded([&] { ms = theViewer().render(width, height).ms; });
  return ms;
}

// Progressive full-quality frames (viewer::Viewer::progressive): the page
// calls tessera_refine once per animation frame while tessera_refining says
// a frame is pending; each call costs about `budgetMs`.
EMSCRIPTEN_KEEPALIVE void tessera_set_progressive(int on, double budgetMs) {
  if (!app().viewer) return;
  theViewer().progressive = on != 0;
  if (budgetMs > 0.0) theViewer().frameBudgetMs = budgetMs;
}
EMSCRIPTEN_KEEPALIVE int tessera_refining() {
  return app().viewer && theViewer().refining() ? 1 : 0;
}
EMSCRIPTEN_KEEPALIVE double tessera_refine() {
  double ms = -1.0;
  guarded([&] { ms = theViewer().refine().ms; });
  return ms;
}

// Pointer input in canvas pixels; action 0 orbit, 1 pan.
EMSCRIPTEN_KEEPALIVE void tessera_pointer_down(int id, double x, double y, int action) {
  if (app().viewer)
    theViewer().controller().pointerDown(
        id, {x, y}, action == 1 ? viewer::PointerAction::Pan : viewer::PointerAction::Orbit);
}
EMSCRIPTEN_KEEPALIVE void tessera_pointer_move(int id, double x, double y) {
  if (app().viewer) theViewer().controller().pointerMove(id, {x, y});
}
EMSCRIPTEN_KEEPALIVE void tessera_pointer_up(int id) {
  if (app().viewer) theViewer().controller().pointerUp(id);
}
EMSCRIPTEN_KEEPALIVE void tessera_wheel(double notches) {
  if (app().viewer) theViewer().controller().wheel(notches);
}
EMSCRIPTEN_KEEPALIVE int tessera_interacting() {
  return app().viewer && theViewer().controller().interacting() ? 1 : 0;
}

// Keeps the projection (tessera_set_projection).
EMSCRIPTEN_KEEPALIVE int tessera_set_camera(double azimuth, double elevation, double zoom) {
  return guarded([&] {
    Camera& c = theViewer().camera();
    const Projection projection = c.projection;
    theViewer().resetCamera();
    c.projection = projection;
    c.azimuthDeg = azimuth;
    c.elevationDeg = elevation;
    c.zoom = zoom;
  });
}

// 1: orthographic (parallel rays; the view's half height is the framed
// radius / zoom), 0: perspective (the default).
EMSCRIPTEN_KEEPALIVE void tessera_set_projection(int orthographic) {
  if (app().viewer)
    theViewer().camera().projection =
        orthographic ? Projection::Orthographic : Projection::Perspective;
}

// Transfer function: JSON in and out (the CLI's format), presets, editor gestures
// in editor units (x in [0,1], y = opacity; channel 0 opacity, 1 colour).
EMSCRIPTEN_KEEPALIVE const char* tessera_tf_json() {
  scratch() = app().viewer ? theViewer().tfEditor().json() : "";
  return scratch().c_str();
}
EMSCRIPTEN_KEEPALIVE int tessera_tf_set_json(const char* json) {
  return guarded([&] { theViewer().tfEditor().loadJson(json); });
}
EMSCRIPTEN_KEEPALIVE int tessera_tf_preset(const char* name) {
  return guarded([&] { theViewer().tfEditor().loadPreset(name); });
}
EMSCRIPTEN_KEEPALIVE void tessera_tf_pointer_down(int channel, double x, double y, double rx,
                                                  double ry) {
  if (app().viewer)
    theViewer().tfEditor().pointerDown(
        channel == 1 ? viewer::TfChannel::Color : viewer::TfChannel::Opacity, {x, y}, {rx, ry});
}
EMSCRIPTEN_KEEPALIVE void tessera_tf_pointer_move(double x, double y) {
  if (app().viewer) theViewer().tfEditor().pointerMove({x, y});
}
EMSCRIPTEN_KEEPALIVE void tessera_tf_pointer_up(double x, double y) {
  if (app().viewer) theViewer().tfEditor().pointerUp({x, y});
}
EMSCRIPTEN_KEEPALIVE int tessera_tf_remove_selected() {
  return app().viewer && theViewer().tfEditor().removeSelected() ? 1 : 0;
}
EMSCRIPTEN_KEEPALIVE void tessera_tf_set_selected_color(double r, double g, double b) {
  if (app().viewer) theViewer().tfEditor().setSelectedColor(toRgb(r, g, b));
}

// Render settings.
EMSCRIPTEN_KEEPALIVE int tessera_set_window(double min, double max) {
  return guarded([&] { theViewer().setWindow({min, max}); });
}
EMSCRIPTEN_KEEPALIVE void tessera_reset_window() {
  if (app().viewer) theViewer().resetWindow();
}
// 0 composite, 1 MIP, 2 MinIP, 3 average (RenderMode's order).
EMSCRIPTEN_KEEPALIVE void tessera_set_mode(int mode) {
  if (app().viewer && mode >= 0 && mode <= 3) {
    theViewer().settings().mode = static_cast<RenderMode>(mode);
  }
}
EMSCRIPTEN_KEEPALIVE int tessera_set_step(double voxels) {
  return guarded([&] {
    if (!(voxels > 0.0 && voxels <= 8.0)) throw InputError("step must be in (0, 8] voxels");
    theViewer().settings().stepVoxels = voxels;
  });
}
// Blinn-Phong shading with a headlight and the default terms (RenderSettings::shading).
EMSCRIPTEN_KEEPALIVE void tessera_set_shading(int on) {
  if (app().viewer) theViewer().settings().shading.enabled = on != 0;
}
EMSCRIPTEN_KEEPALIVE void tessera_set_opacity_scale(double s) {
  if (app().viewer && s >= 0.0) theViewer().settings().opacityScale = s;
}
EMSCRIPTEN_KEEPALIVE void tessera_set_overlays(int box, int axes) {
  if (!app().viewer) return;
  theViewer().showBoundingBox = box != 0;
  theViewer().showAxes = axes != 0;
}
// The most volume pixels a frame renders (0: the canvas's own); the canvas
// keeps its backing size (CSS size x devicePixelRatio) for lines and compositing.
EMSCRIPTEN_KEEPALIVE void tessera_set_max_volume_pixels(int pixels) {
  if (app().viewer) theViewer().maxVolumePixels = std::max(0, pixels);
}
EMSCRIPTEN_KEEPALIVE void tessera_set_quality(int adaptive) {
  if (app().viewer)
    theViewer().quality = adaptive ? viewer::Quality::Adaptive : viewer::Quality::Full;
}
EMSCRIPTEN_KEEPALIVE int tessera_set_technique(const char* name) {
  return guarded([&] { theViewer().setTechnique(name); });
}

// Everything the page shows about the state, as JSON.
EMSCRIPTEN_KEEPALIVE const char* tessera_state_json(int logHistogram) {
  nlohmann::json j;
  if (app().viewer) {
    viewer::Viewer& v = theViewer();
    const gpu::DeviceCaps& caps = v.context().caps();
    j["webgl"] = app().webglVersion;
    j["api"] = gpu::apiLevelName(v.limits().api);
    j["renderer"] = caps.renderer;
    j["gl_version"] = caps.version;
    j["has_volume"] = v.hasVolume();
    j["description"] = v.description();
    j["techniques"] = render::TechniqueRegistry::global().names();
    j["technique"] = v.technique();
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
    j["frame_ms"] = v.lastFrame().ms;
    j["refining"] = v.refining();
    j["render_size"] = {v.lastFrame().renderWidth, v.lastFrame().renderHeight};
    const viewer::TransferFunctionEditor::Selection& s = v.tfEditor().selection();
    j["selection"] = {{"channel", s.channel == viewer::TfChannel::Color ? 1 : 0},
                      {"index", s.index}};
  }
  scratch() = j.dump();
  return scratch().c_str();
}

// The canvas's pixels (RGBA, top row first), for tests and "save image";
// valid until the next call.
EMSCRIPTEN_KEEPALIVE const std::uint8_t* tessera_read_pixels(int width, int height) {
  static std::vector<std::uint8_t> pixels;
  pixels.assign(static_cast<std::size_t>(width) * height * 4, 0);
  std::vector<std::uint8_t> rows(pixels.size());
  gpu::bindFramebuffer(0, {0, 0, width, height});
  gpu::readPixelsRgba8({0, 0, width, height}, rows.data());
  const std::size_t stride = static_cast<std::size_t>(width) * 4;
  for (int y = 0; y < height; ++y) {
    std::copy_n(rows.data() + static_cast<std::size_t>(height - 1 - y) * stride, stride,
                pixels.data() + static_cast<std::size_t>(y) * stride);
  }
  return pixels.data();
}

}  // extern "C"
