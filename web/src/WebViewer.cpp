// The web front end's C++ half: a WebGL context on the page's canvas, the
// shared viewer core on it, and a small C API the page's JavaScript calls
// (web/app.js). Every call that can fail returns 0 and leaves the message in
// tessera_last_error(); the viewer keeps its previous state.
#include <emscripten/emscripten.h>
#include <emscripten/html5.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "ZarrStoreView.h"
#include "tessera/core/Error.h"
#include "tessera/core/Histogram.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/core/SliceImage.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/Draw.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/gpu/MemoryLedger.h"
#include "tessera/io/ByteSource.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/lod/GridNavigator.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/render/LabelTable.h"
#include "tessera/render/OverlayRenderer.h"
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/viewer/CropHandles.h"
#include "tessera/viewer/Explorer.h"
#include "tessera/viewer/Viewer.h"
#include "tessera/viewer/ZoomSwap.h"

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

// The page's default sampling: `tessera render`'s (defaultSampling()) without
// pre-integration. In browsers without a GPU (SwiftShader) the
// pre-integration table's filtered half-float fetch costs more than the
// fewer samples save: on ch2 at 512^2 the page took 1.4-2.0x longer per frame
// pre-integrated than with the adaptive steps alone, which keep 45-48 dB
// against the 0.25-voxel reference (docs/benchmarks.md, "Sampling in the
// browser"). The page's "pre-integrated" control switches it on.
constexpr Sampling webDefaultSampling() {
  Sampling s = defaultSampling();
  s.preintegrate = false;
  return s;
}

viewer::Viewer& theViewer() {
  if (!app().viewer) throw GpuError("the viewer has no WebGL context yet");
  return *app().viewer;
}

void refreshExtraLines();  // region / grid boxes and the crop box (below)
// The zoom swap (below): the whole loaded volume while the zoom drives the
// 3D view (null otherwise); forgetting it (another volume is loaded);
// handing the view back to the whole volume.
const Volume* zoomOverview();
void zoomForget();
void zoomStop();
double zoomFrame(int width, int height);  // a frame of the zoom swap: ms
std::string zoomName();                   // the whole volume's name
// The native block the zoom swap shows (level-0 voxels), nullopt for a level.
std::optional<lod::VoxelBox> zoomBox();

glm::dvec3 toRgb(double r, double g, double b) {
  return {r, g, b};
}

}  // namespace

namespace {
// The region / grid block boxes as lines of the viewer (slices.js, grid.js:
// tessera_set_mark_box), set before each frame.
void applyMarkBoxes();
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
    app().viewer->settings().sampling = webDefaultSampling();
    app().handle = h;
    app().webglVersion = attrs.majorVersion;
  });
}

EMSCRIPTEN_KEEPALIVE const char* tessera_last_error() {
  return lastError().c_str();
}

// "gen:shepp-logan:96" and the other procedural specs of `tessera render`.
EMSCRIPTEN_KEEPALIVE int tessera_load_generated(const char* spec) {
  return guarded([&] {
    zoomForget();
    theViewer().setVolume(makeProcedural(spec), spec);
  });
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
    zoomForget();
    theViewer().setVolume(readVolume(*files.open(name), files), name);
  });
  app().picked.clear();
  return ok;
}

// Renders a frame on the canvas; returns its time in ms (-1 on error).
EMSCRIPTEN_KEEPALIVE double tessera_render(int width, int height) {
  double ms = -1.0;
  guarded([&] {
    refreshExtraLines();
    ms = zoomOverview() ? zoomFrame(width, height) : theViewer().render(width, height).ms;
  });
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
// Pre-integrated classification and adaptive steps (RenderSettings.h: the
// page starts with webDefaultSampling()), each on (1) or off (0).
EMSCRIPTEN_KEEPALIVE void tessera_set_sampling(int preintegrate, int adaptive) {
  if (!app().viewer) return;
  theViewer().settings().sampling.preintegrate = preintegrate != 0;
  theViewer().settings().sampling.preintegrateLitOnly = false;
  theViewer().settings().sampling.adaptive = adaptive != 0;
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

// ---------------------------------------------------------------- slice views and region
// The slice views (web/slices.js): axial, coronal and sagittal slices of the
// loaded volume drawn on the CPU with core/SliceImage (the same pixels and
// patient-direction letters as `tessera slice`), and the bread-slice region
// (Schultz 2016 §7.4): a box of the volume at native resolution shown as the
// 3D view (lod::copyBox, what `tessera render --region` reads for a file),
// the overview kept here to return to.

namespace {

// An open OME-Zarr store (defined with the store's exports below): its
// coarsest level, in memory since open (null when no store is open), and
// its region, level-0 voxels, while the viewer shows it.
const Volume* storeOverview();
web::ZarrStoreView& theZarrView();
struct StoreRegion {
  lod::VoxelBox box;
  bool shown = false;
  Camera overviewCamera;   // the store view's camera, restored on the way back
  bool gridBlock = false;  // read for the grid view (outlined cyan), not picked (red)
};
StoreRegion& storeRegion() {
  static StoreRegion r;
  return r;
}

struct SliceViews {
  // The overview's volume while a region is shown (the viewer holds the
  // region then), its name and camera; null when the overview is shown.
  std::unique_ptr<Volume> overview;
  std::string overviewName;
  Camera overviewCamera;
  lod::VoxelBox region;           // of the overview, voxels (end exclusive)
  const Volume* shown = nullptr;  // the viewer's volume when the region went in
  std::string shownName;
  Image images[3];  // the last slice per axis (tessera_slice's pixels)
};

SliceViews& sliceViews() {
  static SliceViews s;
  return s;
}

// True while the viewer still shows the region this block put in; a volume
// loaded since then (another file) ends region mode.
bool regionShown() {
  SliceViews& s = sliceViews();
  if (!s.overview) return false;
  const viewer::Viewer& v = theViewer();
  if (v.hasVolume() && &v.volume() == s.shown && v.volumeName() == s.shownName) return true;
  s.overview.reset();
  s.shown = nullptr;
  return false;
}

// The volume the slices show: the overview's, also while a region is shown.
const Volume& overviewVolume();

// The voxel space of the slice views, the crosshair, the region and the
// grid: the overview volume's, or an OME-Zarr store's level 0 (its shape:
// dims, spacing, direction and type, no voxels; slices read at the level
// the panel can show, tessera_slice).
const Volume& sliceShape() {
  if (storeOverview()) return theZarrView().store().shape();
  return overviewVolume();
}

const Volume& overviewVolume() {
  if (const Volume* store = storeOverview()) return *store;
  if (const Volume* whole = zoomOverview()) return *whole;
  viewer::Viewer& v = theViewer();
  if (regionShown()) return *sliceViews().overview;
  if (!v.hasVolume()) throw InputError("no volume is loaded");
  return v.volume();
}

// The largest cube side (<= 256, as Schultz's bread-slice textures) whose
// voxels fit the profile: its 3D texture size (or a WebGL 1 atlas of
// side x side tiles in a 2D texture) and what the texture budget leaves
// next to the overview's upload. The planner still has the last word.
std::pair<int, std::string> defaultRegionSide(const Volume& volume) {
  const viewer::Viewer& v = theViewer();
  const gpu::DeviceLimits& l = v.limits();
  const std::uint64_t bpv = bytesPerVoxel(volume.type());
  const gpu::MemoryLedger& ledger = app().context->ledger();
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

}  // namespace

extern "C" {

// Slice `index` along index axis `axis` (0 x, 1 y, 2 z) of the slice views'
// volume (sliceShape) through the viewer's window, nearest voxel at voxel
// centres, grey or (colour != 0) in the colours of the viewer's TF
// (`tessera slice --tf`): JSON with the image (`pixels`: RGBA, top row
// first, image_width x image_height, valid until the next call for this
// axis), its frame (plane, the index axes of columns and rows and whether
// they run reversed; width x height pixels of pixel_mm in the volume's
// voxel space: the image is shown stretched to that) and the patient
// directions of its edges; "" on error (tessera_last_error).
//
// An OME-Zarr store's slice (indices of level 0) is read at the finest level
// whose slice has at most `maxPixels` pixels (the panel's: finer would not
// show; <= 0: level 0), as one slab with bounded reads; until that slab's
// chunks have arrived the coarsest level (in memory) stands in and
// `pending` is true: the page fetches the chunks (tessera_zarr_wanted) and
// asks again. A chunk that keeps failing leaves the coarse slice, with
// `note` naming it.
EMSCRIPTEN_KEEPALIVE const char* tessera_slice(int axis, int index, int colour, double maxPixels) {
  scratch().clear();
  guarded([&] {
    if (axis < 0 || axis > 2) throw InputError("slice: the axis must be 0, 1 or 2");
    const Volume& volume = sliceShape();
    const SliceFrame f = sliceFrame(volume.direction(), axis);
    const glm::ivec3 d = volume.dims();
    if (index < 0 || index >= d[axis]) {
      throw InputError("slice: index " + std::to_string(index) +
                       " is outside 0:" + std::to_string(d[axis]));
    }
    const SliceRaster r = sliceRaster(f, d, volume.spacing());
    Image& image = sliceViews().images[axis];
    viewer::Viewer& v = theViewer();
    const Volume* store = storeOverview();
    // A store's window until a region of it is shown (the viewer's then).
    const ValueRange window = store && !v.hasVolume() ? volume.window() : v.window();
    const TransferFunction* tf = v.sliceColours(colour != 0);
    int level = 0;
    bool pending = false;
    std::string note;
    if (store) {
      const web::FetchedZarrSource& src = theZarrView().source();
      const int coarsest = src.levelCount() - 1;
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
        note = e.what();
      }
      if (ready && level < coarsest) {
        const viewer::SliceGeometry g(li.dims, li.spacing, volume.direction(), axis);
        image = g.render(src, level, slab.begin[axis], window, tf);
      } else {
        pending = note.empty() && level < coarsest;
        level = coarsest;
        image = sliceImage(*store, f, indexAt(coarsest), window, tf);
      }
    } else {
      image = sliceImage(volume, f, index, window, tf);
    }
    nlohmann::json j;
    j["axis"] = axis;
    j["index"] = index;
    j["count"] = d[axis];
    j["plane"] = f.plane;
    j["edges"] = {{"left", f.left}, {"right", f.right}, {"top", f.top}, {"bottom", f.bottom}};
    // Letters only where the file says how the patient lay (as the 3D view).
    j["oriented"] = !volume.geometrySource().empty();
    j["col_axis"] = f.colAxis;
    j["row_axis"] = f.rowAxis;
    j["col_reversed"] = f.colReversed;
    j["row_reversed"] = f.rowReversed;
    j["width"] = r.width;
    j["height"] = r.height;
    j["pixel_mm"] = r.pixelMm;
    j["image_width"] = image.width();
    j["image_height"] = image.height();
    j["level"] = level;
    j["pending"] = pending;
    j["note"] = note;
    j["tf_revision"] = v.tfEditor().revision();
    j["pixels"] = reinterpret_cast<std::uintptr_t>(image.rgba().data());
    scratch() = j.dump();
  });
  return scratch().c_str();
}

// Raw value of voxel (x, y, z) of the slice views' volume (NaN outside
// it). A store's level-0 voxel once its chunk has arrived (the slices fetch
// it when they show level 0; the readout asks for nothing), the coarsest
// level's otherwise.
EMSCRIPTEN_KEEPALIVE double tessera_voxel_value(int x, int y, int z) {
  double value = std::nan("");
  guarded([&] {
    const glm::ivec3 d = sliceShape().dims();
    if (!(x >= 0 && y >= 0 && z >= 0 && x < d.x && y < d.y && z < d.z)) return;
    const Volume* store = storeOverview();
    if (!store) {
      value = overviewVolume().valueAt(x, y, z);
      return;
    }
    const web::FetchedZarrSource& src = theZarrView().source();
    const lod::VoxelBox voxel{{x, y, z}, {x + 1, y + 1, z + 1}};
    if (src.resident(0, voxel)) {
      value = src.readBox(0, voxel).valueAt(0, 0, 0);
      return;
    }
    const glm::ivec3 c = glm::clamp(
        glm::ivec3((glm::dvec3(x, y, z) + 0.5) * glm::dvec3(store->dims()) / glm::dvec3(d)),
        glm::ivec3(0), store->dims() - 1);
    value = store->valueAt(c.x, c.y, c.z);
  });
  return value;
}

// The overview volume and the region: JSON {has_volume, tf_revision, name,
// dims, spacing, region: null or {begin, end}, showing_region, region_side,
// region_side_reason}.
EMSCRIPTEN_KEEPALIVE const char* tessera_explore_json() {
  nlohmann::json j;
  j["has_volume"] = false;
  guarded([&] {
    const Volume* store = app().viewer ? storeOverview() : nullptr;
    if (!app().viewer || (!theViewer().hasVolume() && !store)) return;
    const bool inRegion = store ? storeRegion().shown : regionShown();
    const Volume& volume = sliceShape();
    const glm::ivec3 d = volume.dims();
    const glm::dvec3 sp = volume.spacing();
    j["has_volume"] = true;
    j["tf_revision"] = theViewer().tfEditor().revision();
    j["labels"] = theViewer().labelsOn();  // slices in the label colours
    j["name"] = store            ? theZarrView().storage().describe()
                : inRegion       ? sliceViews().overviewName
                : zoomOverview() ? zoomName()
                                 : theViewer().volumeName();
    j["dims"] = {d.x, d.y, d.z};
    j["spacing"] = {sp.x, sp.y, sp.z};
    j["showing_region"] = inRegion;
    // A store: the slices, crosshair and regions are in level-0 voxels (these
    // dims), the slices read at the level their panel shows (tessera_slice);
    // its region is the box read at level 0 (also as region_level0).
    j["store"] = store != nullptr;
    if (store && inRegion) {
      const lod::VoxelBox& b = storeRegion().box;
      j["region"] = {{"begin", {b.begin.x, b.begin.y, b.begin.z}},
                     {"end", {b.end.x, b.end.y, b.end.z}}};
      j["region_level0"] = j["region"];
    } else if (inRegion) {
      const lod::VoxelBox& b = sliceViews().region;
      j["region"] = {{"begin", {b.begin.x, b.begin.y, b.begin.z}},
                     {"end", {b.end.x, b.end.y, b.end.z}}};
    } else {
      j["region"] = nullptr;
    }
    auto [side, why] = defaultRegionSide(volume);
    j["region_side"] = side;
    j["region_side_reason"] = why;
  });
  scratch() = j.dump();
  return scratch().c_str();
}

// Shows voxels [x0,x1) x [y0,y1) x [z0,z1) of the overview volume, at its
// native resolution, as the 3D view (ends past the volume are clamped; an
// empty box or one that starts outside is an error). The window, the TF and
// the overview stay; tessera_region_overview goes back.
EMSCRIPTEN_KEEPALIVE int tessera_region_show(int x0, int x1, int y0, int y1, int z0, int z1) {
  return guarded([&] {
    zoomStop();  // the region replaces the whole volume, not a level of it
    viewer::Viewer& v = theViewer();
    SliceViews& s = sliceViews();
    const bool inRegion = regionShown();
    const Volume& full = overviewVolume();
    const glm::ivec3 d = full.dims();
    lod::VoxelBox box{{x0, y0, z0}, {x1, y1, z1}};
    const char* names = "xyz";
    for (int a = 0; a < 3; ++a) {
      if (box.begin[a] < 0 || box.begin[a] >= d[a] || box.end[a] <= box.begin[a]) {
        throw InputError(std::string("region: ") + names[a] + " range " +
                         std::to_string(box.begin[a]) + ":" + std::to_string(box.end[a]) +
                         " is empty or starts outside 0:" + std::to_string(d[a]));
      }
      box.end[a] = std::min(box.end[a], d[a]);
    }
    const ValueRange window = v.window();
    Volume region = lod::copyBox(full, box);
    region.setGeometrySource(full.geometrySource());
    region.setWindow(window);
    const std::string overviewName = inRegion ? s.overviewName : v.volumeName();
    const std::string name = overviewName + " region " + std::to_string(box.begin.x) + ":" +
                             std::to_string(box.end.x) + "," + std::to_string(box.begin.y) + ":" +
                             std::to_string(box.end.y) + "," + std::to_string(box.begin.z) + ":" +
                             std::to_string(box.end.z);
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
  });
}

// Back to the overview (with its camera and the current window); the
// region stays known to the page, which draws it as a highlighted box.
EMSCRIPTEN_KEEPALIVE int tessera_region_overview() {
  return guarded([&] {
    if (!regionShown()) return;
    viewer::Viewer& v = theViewer();
    SliceViews& s = sliceViews();
    const ValueRange window = v.window();
    // A copy, so that the overview survives an upload that fails.
    v.setVolume(Volume(*s.overview), s.overviewName);
    v.setWindow(window);
    v.camera() = s.overviewCamera;
    s.overview.reset();
    s.shown = nullptr;
  });
}

}  // extern "C"

namespace {

// Boxes marked in the overview (0: the picked region, red; 1: the grid
// view's last block, cyan), drawn by the viewer as lines composed with the
// volume by depth, like the bounding box and axes (render/HybridCompositor):
// hidden behind opaque tissue, faded behind translucent. Each is kept with
// the dims of the overview it was given for, so that another file never
// shows a stale box.
struct MarkBox {
  std::optional<lod::VoxelBox> box;
  glm::ivec3 dims{0};
};
MarkBox& markBox(int slot) {
  static MarkBox boxes[2];
  return boxes[std::clamp(slot, 0, 1)];
}

void applyMarkBoxes() {
  viewer::Viewer& v = theViewer();
  v.extraLines.clear();
  if (!v.hasVolume() || regionShown()) return;  // the region or block is the view itself
  // The zoom swap's levels span the whole volume (its block is the view).
  const Volume* whole = zoomOverview();
  if (whole && zoomBox()) return;
  const glm::ivec3 dims = whole ? whole->dims() : v.volume().dims();
  const glm::vec4 colours[2] = {{1.0f, 0.25f, 0.2f, 1.0f}, {0.25f, 0.85f, 0.95f, 1.0f}};
  for (int slot = 0; slot < 2; ++slot) {
    const MarkBox& m = markBox(slot);
    if (!m.box || m.dims != dims) continue;
    const auto lines = viewer::boxLines(*m.box, dims, v.volume().extent(), colours[slot]);
    v.extraLines.insert(v.extraLines.end(), lines.begin(), lines.end());
  }
}

}  // namespace

extern "C" {

// Marks box [x0,x1) x [y0,y1) x [z0,z1) of the overview in slot 0 (the
// region, red) or 1 (the grid block, cyan) for the next frames; an empty
// box clears the slot. Clamped to the overview.
EMSCRIPTEN_KEEPALIVE int tessera_set_mark_box(int slot, int x0, int x1, int y0, int y1, int z0,
                                              int z1) {
  return guarded([&] {
    if (slot < 0 || slot > 1) throw InputError("mark box: slot must be 0 or 1");
    MarkBox& m = markBox(slot);
    const lod::VoxelBox box{{x0, y0, z0}, {x1, y1, z1}};
    if (glm::any(glm::lessThanEqual(box.end, box.begin)) || !theViewer().hasVolume()) {
      m.box.reset();
      return;
    }
    m.dims = sliceShape().dims();
    m.box = lod::VoxelBox{glm::clamp(box.begin, glm::ivec3(0), m.dims),
                          glm::clamp(box.end, glm::ivec3(0), m.dims)};
  });
}

// How the 3D view projects the overview's voxel coordinates onto a
// width x height canvas: JSON {mvp (column-major 4x4, model frame to clip
// space, as the viewer's overlay lines), spacing, offset}: a point at
// continuous voxel coordinates p (voxel i spans [i, i+1]) of the overview
// lies at model point p * spacing + offset of the volume the view shows.
EMSCRIPTEN_KEEPALIVE const char* tessera_projection_json(int width, int height) {
  nlohmann::json j;
  guarded([&] {
    viewer::Viewer& v = theViewer();
    if (width <= 0 || height <= 0) return;
    if (storeOverview()) {
      // The slices' voxels are the store's level-0 voxels (sliceShape); its
      // frames are drawn in level 0's model frame (ZarrStoreView::frame), a
      // region of it by the viewer (a box of level 0 placed where it lies).
      const Volume& shape = theZarrView().store().shape();
      const StoreRegion& r = storeRegion();
      const bool inRegion = r.shown && v.hasVolume();
      const glm::dvec3 spacing = shape.spacing();
      const glm::dvec3 extent = inRegion ? v.volume().extent() : shape.extent();
      const glm::dvec3 offset =
          -0.5 * extent - (inRegion ? glm::dvec3(r.box.begin) * shape.spacing() : glm::dvec3(0.0));
      // The store's frames frame the viewer's camera on the store's shape.
      Camera c = v.camera();
      if (!inRegion) c.frame(shape);
      const glm::dmat4 m =
          render::viewProjection(c, double(width) / height, 0.5 * glm::length(extent));
      j["mvp"] = nlohmann::json::array();
      for (int col = 0; col < 4; ++col) {
        for (int row = 0; row < 4; ++row) j["mvp"].push_back(m[col][row]);
      }
      j["spacing"] = {spacing.x, spacing.y, spacing.z};
      j["offset"] = {offset.x, offset.y, offset.z};
      return;
    }
    if (!v.hasVolume()) return;
    const Volume& shownVolume = v.volume();
    glm::dvec3 spacing = shownVolume.spacing();
    glm::dvec3 offset = -0.5 * shownVolume.extent();
    if (regionShown()) offset -= glm::dvec3(sliceViews().region.begin) * spacing;
    if (const Volume* whole = zoomOverview()) {
      // A level spans the whole volume's box; the native block is a box of
      // level 0.
      if (const auto box = zoomBox()) {
        offset -= glm::dvec3(box->begin) * spacing;
      } else {
        spacing = shownVolume.extent() / glm::dvec3(whole->dims());
      }
    }
    const Camera& c = v.camera();
    const double radius = 0.5 * glm::length(shownVolume.extent());
    const glm::dmat4 m = render::viewProjection(c, double(width) / height, radius);
    j["mvp"] = nlohmann::json::array();
    for (int col = 0; col < 4; ++col) {
      for (int row = 0; row < 4; ++row) j["mvp"].push_back(m[col][row]);
    }
    j["spacing"] = {spacing.x, spacing.y, spacing.z};
    j["offset"] = {offset.x, offset.y, offset.z};
  });
  scratch() = j.dump();
  return scratch().c_str();
}

}  // extern "C"

// ---- OME-Zarr stores over fetch() (web/zarr-url.js drives these): the page
// fetches the keys a step wants and hands them over, the store renders
// through the bricks layout coarse to fine (ZarrStoreView.h) with the viewer
// core's camera, transfer function and settings.
namespace {

std::unique_ptr<web::ZarrStoreView>& zarrView() {
  static std::unique_ptr<web::ZarrStoreView> v;
  return v;
}

web::ZarrStoreView& theZarrView() {
  if (!zarrView()) throw Error("no OME-Zarr store is open");
  return *zarrView();
}

const Volume* storeOverview() {
  return zarrView() && zarrView()->isOpen() ? &zarrView()->coarsest() : nullptr;
}

// The grid view's last block over a store (level-0 voxels), while the
// store's overview is drawn (defined with the grid view below).
std::optional<lod::VoxelBox> storeGridBlock();

}  // namespace

extern "C" {

// Starts opening the store at `url` (its root, e.g. http://host/ch2.ome.zarr).
EMSCRIPTEN_KEEPALIVE int tessera_zarr_begin(const char* url) {
  return guarded([&] {
    viewer::Viewer& v = theViewer();
    zoomStop();
    zarrView() = std::make_unique<web::ZarrStoreView>(v.context(), v.limits(), url);
  });
}

// One step of opening: 1 open (the coarsest level is on the GPU), 0 keys
// are wanted (tessera_zarr_wanted), -1 failed (tessera_last_error).
EMSCRIPTEN_KEEPALIVE int tessera_zarr_open_step() {
  int state = -1;
  guarded([&] {
    web::ZarrStoreView& z = theZarrView();
    state = z.open() ? 1 : 0;
    if (state == 1) {
      viewer::Viewer& v = theViewer();
      v.tfEditor().setHistogram(Histogram::compute(z.coarsest(), 256, z.store().shape().window()));
      v.resetCamera();
    }
  });
  return state;
}

// The keys wanted since the last call, most urgent first, as a JSON array.
EMSCRIPTEN_KEEPALIVE const char* tessera_zarr_wanted() {
  nlohmann::json keys = nlohmann::json::array();
  if (zarrView()) {
    for (const std::string& k : zarrView()->storage().takeWanted()) keys.push_back(k);
  }
  scratch() = keys.dump();
  return scratch().c_str();
}

// 1 when the key has arrived (or is known missing, or failed moments ago):
// the page does not fetch it again when it is listed twice.
EMSCRIPTEN_KEEPALIVE int tessera_zarr_holds(const char* key) {
  return zarrView() && zarrView()->storage().holds(key) ? 1 : 0;
}

// A fetched key: its bytes (malloc'ed by the page, freed here), a 404, or
// the page's error after its retries (naming the URL).
EMSCRIPTEN_KEEPALIVE void tessera_zarr_put(const char* key, std::uint8_t* bytes, int size) {
  const std::unique_ptr<std::uint8_t, decltype(&std::free)> owned(bytes, &std::free);
  if (!zarrView()) return;
  const auto* b = reinterpret_cast<const std::byte*>(bytes);
  zarrView()->storage().put(key, std::vector<std::byte>(b, b + std::max(0, size)));
}
EMSCRIPTEN_KEEPALIVE void tessera_zarr_put_missing(const char* key) {
  if (zarrView()) zarrView()->storage().putMissing(key);
}
EMSCRIPTEN_KEEPALIVE void tessera_zarr_put_failed(const char* key, const char* message) {
  if (zarrView()) zarrView()->storage().putFailed(key, message);
}

// The page decodes chunks of this compressor ("blosc", "zstd") itself
// (numcodecs, web/zarr-url.js) before it hands them over.
EMSCRIPTEN_KEEPALIVE int tessera_zarr_page_decodes(const char* compressor) {
  return guarded([&] { theZarrView().storage().setPageDecodes(parseZarrCompressor(compressor)); });
}

// A frame of the open store on the canvas: JSON with the bricks' state
// ("complete", "wanted", "missing", "failing", "uploaded", cells per level),
// or "" on error (tessera_last_error).
EMSCRIPTEN_KEEPALIVE const char* tessera_zarr_frame(int width, int height) {
  scratch().clear();
  guarded([&] {
    viewer::Viewer& v = theViewer();
    web::ZarrStoreView& z = theZarrView();
    // The picked region as a red box over the store, as over a file's
    // overview (applyMarkBoxes), composed by depth.
    std::vector<render::OverlayLine> marks;
    const StoreRegion& r = storeRegion();
    const Volume& shape = z.store().shape();
    if (!r.gridBlock && glm::all(glm::lessThan(r.box.begin, r.box.end))) {
      marks = viewer::boxLines(r.box, shape.dims(), shape.extent(), {1.0f, 0.25f, 0.2f, 1.0f});
    }
    // The grid view's last block, cyan (level-0 voxels, as the region).
    if (const std::optional<lod::VoxelBox> block = storeGridBlock()) {
      const auto cyan =
          viewer::boxLines(*block, shape.dims(), shape.extent(), {0.25f, 0.85f, 0.95f, 1.0f});
      marks.insert(marks.end(), cyan.begin(), cyan.end());
    }
    const web::StoreFrame f = z.frame(
        v.camera(), v.frameSettings(), v.tfEditor().transferFunction(), v.tfEditor().revision(),
        v.showBoundingBox, v.showAxes, width, height, v.maxVolumePixels, marks);
    const lod::StreamerStats s = z.bricks().streamerStats();
    const web::FetchStats fetched = z.storage().stats();
    nlohmann::json j;
    j["ms"] = f.ms;
    j["render_size"] = {f.renderWidth, f.renderHeight};
    j["complete"] = f.bricks.complete;
    j["wanted"] = f.bricks.wanted;
    j["missing"] = f.bricks.missing;
    j["failing"] = f.bricks.failing;
    j["uploaded"] = f.bricks.uploaded;
    j["limited_by_budget"] = f.bricks.limitedByBudget;
    j["wanted_per_level"] = f.bricks.wantedPerLevel;
    j["cells_per_level"] = f.bricks.cellsPerLevel;  // last: transparent cells
    j["bricks_read"] = s.bricksRead;
    j["read_errors"] = s.readErrors;
    j["last_error"] = s.lastError;
    j["fetched_keys"] = fetched.keys;
    j["fetched_bytes"] = fetched.bytes;
    j["fetch_failures"] = fetched.failed;
    j["held_bytes"] = fetched.heldBytes;
    scratch() = j.dump();
  });
  return scratch().c_str();
}

// The open store: its description, levels and the bricks layout's plan.
EMSCRIPTEN_KEEPALIVE const char* tessera_zarr_info() {
  scratch().clear();
  guarded([&] {
    const web::ZarrStoreView& z = theZarrView();
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
    scratch() = j.dump();
  });
  return scratch().c_str();
}

}  // extern "C"

namespace {

// The bread-slice region of a store: voxels [x0,x1) x [y0,y1) x
// [z0,z1) of level 0, read with bounded reads: only the chunks overlapping
// the box are fetched (asynchronously, by the page), then one readBox, never
// the level whole. Ends past the level are clamped; an empty box or one
// that starts outside is an error naming the store.
lod::VoxelBox storeRegionBox(web::ZarrStoreView& z, int x0, int x1, int y0, int y1, int z0,
                             int z1) {
  const glm::ivec3 d = z.source().levelInfo(0).dims;
  lod::VoxelBox box{{x0, y0, z0}, {x1, y1, z1}};
  const char* names = "xyz";
  for (int a = 0; a < 3; ++a) {
    if (box.begin[a] < 0 || box.begin[a] >= d[a] || box.end[a] <= box.begin[a]) {
      throw InputError(z.storage().describe() + ": region: " + names[a] + " range " +
                       std::to_string(box.begin[a]) + ":" + std::to_string(box.end[a]) +
                       " is empty or starts outside 0:" + std::to_string(d[a]) + " of level 0");
    }
    box.end[a] = std::min(box.end[a], d[a]);
  }
  return box;
}

}  // namespace

extern "C" {

// 1 when every level-0 chunk of the box has arrived, 0 when some are wanted
// (tessera_zarr_wanted lists them: the page fetches them and asks again),
// -1 on error (tessera_last_error).
EMSCRIPTEN_KEEPALIVE int tessera_zarr_region_prefetch(int x0, int x1, int y0, int y1, int z0,
                                                      int z1) {
  int state = -1;
  guarded([&] {
    web::ZarrStoreView& z = theZarrView();
    if (!z.isOpen()) throw Error(z.storage().describe() + ": the store is not open yet");
    state = z.source().prefetch(0, storeRegionBox(z, x0, x1, y0, y1, z0, z1)) ? 1 : 0;
  });
  return state;
}

// Reads the box (its chunks fetched: tessera_zarr_region_prefetch) at level
// 0 and makes it the viewer's volume, placed and windowed as in the store
// (what `tessera render STORE --region` reads); the page then draws the
// viewer instead of the store until it goes back to the store's overview.
EMSCRIPTEN_KEEPALIVE int tessera_zarr_region_show(int x0, int x1, int y0, int y1, int z0, int z1) {
  return guarded([&] {
    web::ZarrStoreView& z = theZarrView();
    const lod::VoxelBox box = storeRegionBox(z, x0, x1, y0, y1, z0, z1);
    if (!z.source().prefetch(0, box)) {
      throw Error(z.storage().describe() + ": region: its chunks have not all arrived");
    }
    Volume region = z.source().readBox(0, box);
    region.setWindow(z.store().shape().window());
    const ValueRange window = region.window();
    viewer::Viewer& v = theViewer();
    const Camera camera = v.camera();
    const auto text = [&](int a) {
      return std::to_string(box.begin[a]) + ":" + std::to_string(box.end[a]);
    };
    StoreRegion& r = storeRegion();
    // From the store view (not from another region of it): its camera.
    if (!r.shown) r.overviewCamera = camera;
    r.box = box;
    r.shown = true;
    r.gridBlock = false;  // tessera_grid_store_shown says when it is the grid's
    v.setVolume(std::move(region),
                z.storage().describe() + " region " + text(0) + "," + text(1) + "," + text(2));
    v.setWindow(window);
    // Framed on the region (setVolume), seen from the store view's
    // direction, projection and zoom.
    Camera& c = v.camera();
    c.projection = camera.projection;
    c.azimuthDeg = camera.azimuthDeg;
    c.elevationDeg = camera.elevationDeg;
    c.zoom = camera.zoom;
  });
}

// Back to the store's overview from its region (the page draws the store
// again; the region stays known, for its outline in the slice views).
EMSCRIPTEN_KEEPALIVE void tessera_zarr_region_overview() {
  StoreRegion& r = storeRegion();
  if (r.shown && app().viewer) theViewer().camera() = r.overviewCamera;
  r.shown = false;
}

// Closes the store (the viewer core's volume shows again).
EMSCRIPTEN_KEEPALIVE void tessera_zarr_close() {
  zarrView().reset();
  storeRegion() = {};
}

}  // extern "C"

// ---------------------------------------------------------------- grid view
// The grid view (web/grid.js): Schultz 2016 §7.3's grid view over
// the loaded volume, with the native core's lod::GridNavigator (the grid
// points, their classes, the legal moves and the moves chosen by the view
// direction are all its own; the page only shows them). The 2x2x2 block of
// cells around the current grid point is shown as the 3D view at native
// resolution the way the bread-slice region is (tessera_region_show:
// lod::copyBox of the loaded volume), so "Overview" / Esc
// (tessera_region_overview) returns from either.

namespace {

struct GridView {
  std::optional<lod::GridNavigator> nav;
  std::string volumeKey;               // the overview it was made for: name and dims
  int askedCell = 0;                   // the cell side asked for (0: the default)
  std::string shownName;               // the viewer's volume name while its block is shown
  std::optional<lod::VoxelBox> block;  // the last block shown
  std::string note;                    // the last move, or why it was refused
  bool refused = false;
  bool storeWanted = false;  // a store's block is to be read (the page fetches its chunks)
  // Where a store's pending block came from: restored when its read fails.
  glm::ivec3 fromPoint{0};
  std::optional<lod::VoxelBox> fromBlock;
  std::string fromShownName;
};

GridView& gridView() {
  static GridView g;
  return g;
}

// The grid is over the slices' voxels (sliceShape: a store's level 0, where
// its blocks are read like its regions; a file's overview volume).
std::string overviewKey(const Volume& v) {
  const glm::ivec3 d = v.dims();
  if (storeOverview()) {
    return "store:" + theZarrView().storage().describe() + "|" + std::to_string(d.x) + "x" +
           std::to_string(d.y) + "x" + std::to_string(d.z);
  }
  const std::string name = regionShown()    ? sliceViews().overviewName
                           : zoomOverview() ? zoomName()
                                            : theViewer().volumeName();
  return name + "|" + std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

// True while the 3D view shows the block this block put in (not a region
// picked since, nor the overview, nor another file).
bool gridShown() {
  const GridView& g = gridView();
  if (storeOverview()) {
    const StoreRegion& r = storeRegion();
    return !g.shownName.empty() && r.shown && g.block && r.box.begin == g.block->begin &&
           r.box.end == g.block->end && theViewer().volumeName() == g.shownName;
  }
  return !g.shownName.empty() && regionShown() && sliceViews().shownName == g.shownName;
}

std::optional<lod::VoxelBox> storeGridBlock() {
  const GridView& g = gridView();
  if (!g.block || g.storeWanted || !storeOverview() || storeRegion().shown) return std::nullopt;
  return g.block;
}

// The default cell: cubic, a multiple of 16 voxels, as large as possible
// while the 2x2x2 block fits the region's default side cubed (what the
// profile's texture size and budget allow, at most 256³), and no larger
// than a quarter of the longest axis (Schultz's 4x4x4 split), so that a
// volume that fits the budget whole still has a grid to move on.
lod::GridNavigator defaultGrid(const Volume& volume) {
  const int side = defaultRegionSide(volume).first;
  const glm::ivec3 d = volume.dims();
  const int budgetCell =
      lod::GridNavigator::forBudget(d, std::uint64_t(side) * side * side, 16).cellSize().x;
  const int quarter = (std::max({d.x, d.y, d.z}) + 3) / 4;
  const int splitCell = std::max(16, (quarter + 15) / 16 * 16);
  return lod::GridNavigator(d, glm::ivec3(std::min(budgetCell, splitCell)));
}

// The navigator for the overview volume now (made anew for another volume
// or another cell side; `cellSide` < 0 keeps the current one).
lod::GridNavigator& gridFor(const Volume& volume, int cellSide) {
  GridView& g = gridView();
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

std::string boxText(const lod::VoxelBox& b) {
  return std::to_string(b.begin.x) + ":" + std::to_string(b.end.x) + "," +
         std::to_string(b.begin.y) + ":" + std::to_string(b.end.y) + "," +
         std::to_string(b.begin.z) + ":" + std::to_string(b.end.z);
}

// Shows `box` of the overview as the 3D view. The view direction and the
// projection stay (the moves are chosen from it); the zoom too on a move,
// 1 on entering (the block fills the view).
void showGridBlock(const lod::VoxelBox& box, bool keepZoom) {
  GridView& g = gridView();
  if (storeOverview()) {
    // A store's block is read like its region (tessera_zarr_region_prefetch
    // / _show): the page fetches exactly its level-0 chunks, then calls
    // tessera_grid_store_shown.
    if (!g.storeWanted) {
      g.fromBlock = g.block;
      g.fromShownName = g.shownName;
    }
    g.block = box;
    g.storeWanted = true;
    g.shownName.clear();
    return;
  }
  viewer::Viewer& v = theViewer();
  const Camera before = v.camera();
  if (!tessera_region_show(box.begin.x, box.end.x, box.begin.y, box.end.y, box.begin.z,
                           box.end.z)) {
    throw InputError("grid view: " + std::string(lastError()));
  }
  Camera& c = v.camera();
  c.projection = before.projection;
  c.azimuthDeg = before.azimuthDeg;
  c.elevationDeg = before.elevationDeg;
  c.zoom = keepZoom ? before.zoom : 1.0;
  g.shownName = sliceViews().shownName;
  g.block = box;
}

const lod::ViewMove kViewMoves[6] = {lod::ViewMove::Forward, lod::ViewMove::Back,
                                     lod::ViewMove::Left,    lod::ViewMove::Right,
                                     lod::ViewMove::Up,      lod::ViewMove::Down};

}  // namespace

extern "C" {

// Enters the grid view (or starts it again) at the grid point nearest the
// centre of voxel (x, y, z) of the overview (the crosshair), with cubic
// cells of `cellSide` voxels (0: the default for the profile, -1: as
// before), and shows that point's block.
EMSCRIPTEN_KEEPALIVE int tessera_grid_enter(int cellSide, int x, int y, int z) {
  return guarded([&] {
    zoomStop();  // the grid view's block replaces the whole volume
    const Volume& volume = sliceShape();
    lod::GridNavigator& nav = gridFor(volume, cellSide);
    // The crosshair is in the slices' voxels, as the grid.
    const glm::dvec3 c = (glm::dvec3(x, y, z) + 0.5) / glm::dvec3(nav.cellSize());
    if (!gridView().storeWanted) gridView().fromPoint = nav.point();
    nav.moveTo(glm::clamp(glm::ivec3(glm::round(c)), glm::ivec3(0), nav.cells()));
    showGridBlock(nav.blockBox(nav.point()), false);
    GridView& g = gridView();
    g.note = "grid point " + nav.describe(nav.point());
    g.refused = false;
  });
}

// One of the six moves relative to the view (0 forward, 1 back, 2 left,
// 3 right, 4 up, 5 down; lod::viewMoveToGridMove with the 3D view's camera):
// 1 moved (the new block is shown), 0 refused at the grid's boundary (the
// reason in tessera_grid_json's note; nothing changes), -1 error.
EMSCRIPTEN_KEEPALIVE int tessera_grid_move(int viewMove) {
  int result = -1;
  guarded([&] {
    if (viewMove < 0 || viewMove > 5) throw InputError("grid view: moves are 0..5");
    if (!gridShown() && !gridView().storeWanted) {
      throw InputError("grid view: not in the grid view (press G)");
    }
    viewer::Viewer& v = theViewer();
    lod::GridNavigator& nav = gridFor(sliceShape(), -1);
    const lod::ViewMove vm = kViewMoves[viewMove];
    const lod::GridMove m = lod::viewMoveToGridMove(v.camera().basis(), vm);
    const std::string what = std::string(lod::viewMoveName(vm)) + " = " + m.name();
    GridView& g = gridView();
    const glm::ivec3 from = nav.point();
    if (!g.storeWanted) g.fromPoint = from;
    const lod::MoveResult r = nav.apply(m);
    if (!r.moved) {
      g.note = what + " refused: " + r.reason;
      g.refused = true;
      result = 0;
      return;
    }
    try {
      showGridBlock(nav.blockBox(nav.point()), true);
    } catch (...) {
      nav.moveTo(from);
      throw;
    }
    g.note = what + ": grid point " + nav.describe(nav.point());
    g.refused = false;
    result = 1;
  });
  return result;
}

// The grid view: JSON {has_volume, active (its block is the 3D view),
// cell_size, cells, point, point_class, describe, block (the last block
// shown, the slices' voxels, end exclusive; null before the first),
// block_text, moves (per view move: its name, the grid move, legal and why
// not), note, refused, default_cell}.
EMSCRIPTEN_KEEPALIVE const char* tessera_grid_json() {
  nlohmann::json j;
  j["has_volume"] = false;
  guarded([&] {
    if (!app().viewer || (!theViewer().hasVolume() && !storeOverview())) return;
    if (storeOverview() && !theZarrView().isOpen()) return;
    const Volume& volume = sliceShape();
    lod::GridNavigator& nav = gridFor(volume, -1);
    const GridView& g = gridView();
    const glm::ivec3 cs = nav.cellSize(), cells = nav.cells(), p = nav.point();
    j["has_volume"] = true;
    j["active"] = gridShown();
    j["cell_size"] = {cs.x, cs.y, cs.z};
    j["cells"] = {cells.x, cells.y, cells.z};
    j["point"] = {p.x, p.y, p.z};
    j["point_class"] = lod::gridPointClassName(nav.pointClass());
    j["describe"] = nav.describe(p);
    if (g.block) {
      const lod::VoxelBox& b = *g.block;
      j["block"] = {{"begin", {b.begin.x, b.begin.y, b.begin.z}},
                    {"end", {b.end.x, b.end.y, b.end.z}}};
      j["block_text"] = boxText(b);
    } else {
      j["block"] = nullptr;
    }
    j["moves"] = nlohmann::json::array();
    const glm::dmat3 basis = theViewer().camera().basis();
    for (const lod::ViewMove vm : kViewMoves) {
      const lod::GridMove m = lod::viewMoveToGridMove(basis, vm);
      const lod::MoveResult r = nav.check(p, m);
      j["moves"].push_back({{"view", lod::viewMoveName(vm)},
                            {"move", m.name()},
                            {"legal", r.moved},
                            {"reason", r.reason}});
    }
    j["note"] = g.note;
    j["refused"] = g.refused;
    j["default_cell"] = defaultGrid(volume).cellSize().x;
    // A store: the block (level-0 voxels) the page is to fetch and show
    // (tessera_zarr_region_prefetch / _show, then tessera_grid_store_shown).
    j["store"] = storeOverview() != nullptr;
    j["store_wanted"] = g.storeWanted;
  });
  scratch() = j.dump();
  return scratch().c_str();
}

// A store's block could not be read (its chunks kept failing): the grid
// point and block go back to where they were before the enter or move that
// asked for it (the 3D view still shows that block, or the store), with a
// note saying so.
EMSCRIPTEN_KEEPALIVE int tessera_grid_store_failed() {
  return guarded([&] {
    GridView& g = gridView();
    if (!g.storeWanted || !g.nav) return;
    g.nav->moveTo(g.fromPoint);
    g.block = g.fromBlock;
    g.shownName = g.fromShownName;
    g.storeWanted = false;
    g.note = "the block could not be read; back at grid point " + g.nav->describe(g.fromPoint);
    g.refused = true;
  });
}

// A store's block (tessera_grid_json's block) has been read and shown by
// tessera_zarr_region_show: it is now the grid view's.
EMSCRIPTEN_KEEPALIVE int tessera_grid_store_shown() {
  return guarded([&] {
    GridView& g = gridView();
    const StoreRegion& r = storeRegion();
    if (!g.storeWanted || !g.block || !r.shown || r.box.begin != g.block->begin ||
        r.box.end != g.block->end) {
      throw InputError("grid view: the store's block has not been read");
    }
    g.storeWanted = false;
    g.shownName = theViewer().volumeName();
    storeRegion().gridBlock = true;
  });
}

}  // extern "C"

// ---- Light, clipping and the crop box's handles ----

namespace {

struct CropState {
  bool show = false;  // the crop box and its handles in the 3D view
  viewer::CropHandles handles;
};

CropState& cropState() {
  static CropState s;
  return s;
}

// The crop box's lines go into the viewer's extra lines (the page draws its
// other marks on a 2D canvas), composed by depth like the bounding box.
// The viewer's extra lines: the region / grid boxes (applyMarkBoxes()), then
// the crop box's.
void refreshExtraLines() {
  if (!app().viewer) return;
  applyMarkBoxes();
  viewer::Viewer& v = theViewer();
  if (cropState().show && v.hasVolume()) {
    const auto lines = viewer::CropHandles::lines(v.settings().clipping, v.volume().extent(),
                                                  cropState().handles.dragging());
    v.extraLines.insert(v.extraLines.end(), lines.begin(), lines.end());
  }
}

}  // namespace

extern "C" {

// Blinn-Phong terms and the light: a headlight, or a fixed light from
// (lx, ly, lz) in the patient frame (RAS+, towards the light).
EMSCRIPTEN_KEEPALIVE int tessera_set_light(int headlight, double ambient, double diffuse,
                                           double specular, double shininess, double lx, double ly,
                                           double lz) {
  return guarded([&] {
    const glm::dvec3 dir(lx, ly, lz);
    if (!headlight && glm::length(dir) < 1e-6)
      throw InputError("the fixed light needs a direction");
    Shading& s = theViewer().settings().shading;
    s.headlight = headlight != 0;
    s.ambient = std::clamp(ambient, 0.0, 1.0);
    s.diffuse = std::clamp(diffuse, 0.0, 1.0);
    s.specular = std::clamp(specular, 0.0, 1.0);
    s.shininess = std::clamp(shininess, 1.0, 256.0);
    if (!s.headlight) s.lightDirection = dir;
  });
}

// Gradient-magnitude opacity modulation (Shading::gradientOpacity): opacity
// times clamp((|g| - low) / (high - low), 0, 1), with or without the light
// (`tessera render --gradient-opacity on|LOW,HIGH`).
EMSCRIPTEN_KEEPALIVE int tessera_set_gradient_opacity(int on, double low, double high) {
  return guarded([&] {
    if (!(low >= 0.0 && high > low)) {
      throw InputError("gradient opacity: needs 0 <= low < high (got " + std::to_string(low) +
                       ", " + std::to_string(high) + ")");
    }
    Shading& s = theViewer().settings().shading;
    s.gradientOpacity = on != 0;
    s.gradientLow = low;
    s.gradientHigh = high;
  });
}

// The crop box in fractions of each index axis (0..1, min < max).
EMSCRIPTEN_KEEPALIVE int tessera_set_crop(double x0, double x1, double y0, double y1, double z0,
                                          double z1) {
  return guarded([&] {
    const glm::dvec3 lo(x0, y0, z0), hi(x1, y1, z1);
    for (int a = 0; a < 3; ++a) {
      if (!(lo[a] >= 0.0 && hi[a] <= 1.0 && lo[a] < hi[a])) {
        throw InputError(std::string("crop box: ") + "xyz"[a] +
                         " must satisfy 0 <= min < max <= 1");
      }
    }
    theViewer().settings().clipping.cropMin = lo;
    theViewer().settings().clipping.cropMax = hi;
    refreshExtraLines();
  });
}
EMSCRIPTEN_KEEPALIVE void tessera_show_crop_box(int on) {
  cropState().show = on != 0;
  refreshExtraLines();
}
// The crop box as JSON {"min": [x, y, z], "max": [...], "handles": [[px,
// py] per face (-x, +x, -y, +y, -z, +z) on a width x height canvas]}.
EMSCRIPTEN_KEEPALIVE const char* tessera_crop_json(int width, int height) {
  nlohmann::json j;
  if (app().viewer) {
    viewer::Viewer& v = theViewer();
    const Clipping& c = v.settings().clipping;
    if (v.hasVolume() && width > 0 && height > 0) {
      j["handles"] = nlohmann::json::array();
      for (int f = 0; f < viewer::kCropFaces; ++f) {
        const auto p = viewer::projectToScreen(
            v.camera(), viewer::CropHandles::faceCentre(c, v.volume().extent(), f), width, height);
        j["handles"].push_back(p ? nlohmann::json{p->pixel.x, p->pixel.y} : nlohmann::json());
      }
    }
    j["min"] = {c.cropMin.x, c.cropMin.y, c.cropMin.z};
    j["max"] = {c.cropMax.x, c.cropMax.y, c.cropMax.z};
    j["show"] = cropState().show;
    j["dragging"] = cropState().handles.dragging() ? *cropState().handles.dragging() : -1;
  }
  scratch() = j.dump();
  return scratch().c_str();
}
// A pointer pressed at canvas pixel (x, y) of a width x height canvas: 1 when
// it grabbed a crop box handle (the page then sends moves here, not to the
// camera), else 0.
EMSCRIPTEN_KEEPALIVE int tessera_crop_pointer_down(double x, double y, int width, int height,
                                                   double radiusPx) {
  if (!app().viewer || !cropState().show || !theViewer().hasVolume()) return 0;
  viewer::Viewer& v = theViewer();
  const glm::dvec3 extent = v.volume().extent();
  const auto face = viewer::CropHandles::hit(v.camera(), v.settings().clipping, extent, {x, y},
                                             width, height, radiusPx);
  if (!face) return 0;
  cropState().handles.begin(v.camera(), v.settings().clipping, extent, *face, {x, y}, width,
                            height);
  refreshExtraLines();
  return 1;
}
// 1 when the box changed.
EMSCRIPTEN_KEEPALIVE int tessera_crop_pointer_move(double x, double y) {
  if (!app().viewer) return 0;
  const bool changed = cropState().handles.move({x, y}, theViewer().settings().clipping);
  if (changed) refreshExtraLines();
  return changed ? 1 : 0;
}
EMSCRIPTEN_KEEPALIVE void tessera_crop_pointer_up() {
  cropState().handles.end();
  refreshExtraLines();
}
// The clip plane that follows the camera (viewer::cameraFacingPlane), at
// `depth` x half the volume's diagonal from its centre towards the viewer
// (-1..1: the whole volume).
EMSCRIPTEN_KEEPALIVE void tessera_set_following_plane(int on, double depth) {
  if (!app().viewer) return;
  viewer::Viewer& v = theViewer();
  v.clipPlaneFollowsCamera = on != 0;
  const double reach = v.hasVolume() ? 0.5 * glm::length(v.volume().extent()) : 0.0;
  v.followingPlaneDistance = std::clamp(depth, -1.0, 1.0) * reach;
}

}  // extern "C"

// ---- Label volumes (atlases), as `tessera render --labels` shows them
// (viewer::Viewer::setLabels). The page's label table file goes through
// render::LabelTable's parsers: JSON when it starts with '{', else a label
// text file (ITK-SNAP, FreeSurfer, mricron); errors name the file and line.
extern "C" {

// on = 0: an ordinary volume again (the TF preset `mr-default`). on = 1:
// labels, with `table` (the file's text, named `name`) or, when empty, the
// default palette. 0 on error (tessera_last_error), the state unchanged.
EMSCRIPTEN_KEEPALIVE int tessera_set_labels(int on, const char* table, const char* name) {
  return guarded([&] {
    if (on != 0) zoomStop();  // labels are not averaged into coarser levels
    viewer::Viewer& v = theViewer();
    if (on == 0) {
      v.clearLabels();
      return;
    }
    const std::string text = table;
    if (text.empty()) {
      v.setLabelsDefault();
      return;
    }
    const auto first = text.find_first_not_of(" \t\r\n");
    const bool json = first != std::string::npos && text[first] == '{';
    v.setLabels(json ? render::LabelTable::fromJson(text, name)
                     : render::LabelTable::fromText(text, name));
  });
}
// {"on": bool, "labels": [{"value", "name", "color": [r, g, b] 0..1, "visible"}]}
EMSCRIPTEN_KEEPALIVE const char* tessera_labels_json() {
  nlohmann::json j;
  const bool on = app().viewer && theViewer().labelsOn();
  j["on"] = on;
  j["labels"] = nlohmann::json::array();
  if (on) {
    for (const auto& [value, label] : theViewer().labelTable().labels) {
      j["labels"].push_back({{"value", value},
                             {"name", label.name},
                             {"color", {label.color.r, label.color.g, label.color.b}},
                             {"visible", label.visible}});
    }
  }
  scratch() = j.dump();
  return scratch().c_str();
}
// value < 0: every label.
EMSCRIPTEN_KEEPALIVE void tessera_set_label_visible(int value, int visible) {
  if (!app().viewer) return;
  if (value < 0) {
    theViewer().setAllLabelsVisible(visible != 0);
  } else {
    theViewer().setLabelVisible(value, visible != 0);
  }
}

}  // extern "C"

// ---- Zoom-driven level swap (Schultz 2016 §7.3.1), the
// desktop viewer's viewer::ZoomSwap on the page: zoomed out the 3D view
// shows a coarse level of the loaded volume, then the medium level (the
// finest that fits the profile's overview budget), then, zoomed in far
// enough, the native 2x2x2 grid block around the view's centre; each swap
// keeps the camera (every patient point stays on screen) and cross-fades.
// The page's slice views, crosshair, region and grid keep working on the
// whole loaded volume (held here while the zoom drives the view); picking
// a region, entering the grid view, labels or another volume hand the view
// back to the whole volume first.
namespace {

struct ZoomView {
  std::shared_ptr<const Volume> whole;  // the loaded volume (level 0 of the pyramid)
  std::string name;                     // its name
  std::unique_ptr<viewer::Explorer> explorer;
  std::unique_ptr<viewer::ZoomSwap> swap;  // after the explorer: it holds a reference
  int mediumLevel = 0;
  double lastFrameMs = -1.0;
  std::string shownName;  // the viewer's volume after the last frame
};

ZoomView& zoomView() {
  static ZoomView z;
  return z;
}

// A frame's time step for the fade, at most this: a fade spans at least
// 250 / 100 + 1 frames however slow a frame is (a software rasteriser's
// 300 ms frame would otherwise end it in one: a pop).
constexpr double kMaxFadeStepMs = 100.0;

// True while the zoom swap drives the viewer (a volume loaded since ends it).
bool zoomActive() {
  ZoomView& z = zoomView();
  if (!z.swap || !app().viewer) return false;
  const viewer::Viewer& v = theViewer();
  if (v.hasVolume() && v.volumeName() == z.shownName) return true;
  z = ZoomView();
  return false;
}

const Volume* zoomOverview() {
  return zoomActive() ? zoomView().whole.get() : nullptr;
}

std::string zoomName() {
  return zoomView().name;
}

std::optional<lod::VoxelBox> zoomBox() {
  return zoomActive() ? zoomView().swap->shownBox() : std::nullopt;
}

void zoomForget() {
  zoomView() = ZoomView();
}

void zoomStop() {
  if (!zoomActive()) {
    zoomForget();
    return;
  }
  ZoomView& z = zoomView();
  viewer::Viewer& v = theViewer();
  const Camera before = v.camera();
  const ValueRange window = v.window();
  const std::optional<lod::VoxelBox> box = z.swap->shownBox();
  std::shared_ptr<const Volume> whole = z.whole;
  const std::string name = z.name;
  v.setVolume(Volume(*whole), name);  // throws with the zoom swap still on
  zoomForget();
  v.setWindow(window);
  v.camera() = viewer::cameraAcrossSwap(before, box, std::nullopt, whole->dims(), whole->spacing());
}

double zoomFrame(int width, int height) {
  ZoomView& z = zoomView();
  viewer::Viewer& v = theViewer();
  const double now = emscripten_get_now();
  const double dt = z.lastFrameMs < 0.0 ? 0.0 : std::min(now - z.lastFrameMs, kMaxFadeStepMs);
  z.lastFrameMs = now;
  z.swap->frame(v, dt, width, height);
  z.shownName = v.volumeName();
  return emscripten_get_now() - now;
}

}  // namespace

extern "C" {

// on = 1: the zoom drives the 3D view of the loaded file (stages for a view
// `viewPixels` high; `overviewVoxels` > 0 replaces the profile's overview
// budget and `blockVoxels` > 0 its native block budget, e.g. to see all
// three stages on a small volume). on = 0: the whole volume again, with the
// camera kept. 0 on error (tessera_last_error), nothing changed.
EMSCRIPTEN_KEEPALIVE int tessera_zoom_swap(int on, int viewPixels, double overviewVoxels,
                                           double blockVoxels) {
  return guarded([&] {
    if (on == 0) {
      zoomStop();
      return;
    }
    viewer::Viewer& v = theViewer();
    if (storeOverview()) {
      throw InputError(
          "zoom swap: an OME-Zarr store already refines with the zoom (its bricks' level "
          "selection); the zoom swap is for files");
    }
    if (v.labelsOn()) {
      throw InputError("zoom swap: not for a label volume (coarser levels would average labels)");
    }
    tessera_region_overview();
    zoomStop();
    if (!v.hasVolume()) throw InputError("zoom swap: no volume is loaded");
    ZoomView z;
    z.whole = std::make_shared<const Volume>(v.volume());
    z.name = v.volumeName();
    auto source = std::make_shared<const lod::InCoreMultiresSource>(z.whole);
    const gpu::DeviceLimits& limits = v.limits();
    const std::uint64_t bpv = bytesPerVoxel(z.whole->type());
    const std::uint64_t blockBytes = blockVoxels > 0.0
                                         ? static_cast<std::uint64_t>(blockVoxels) * bpv
                                         : viewer::regionBudgetBytes(limits);
    z.explorer = std::make_unique<viewer::Explorer>(source, blockBytes);
    z.mediumLevel =
        z.explorer->overviewLevel(overviewVoxels > 0.0 ? static_cast<std::uint64_t>(overviewVoxels)
                                                       : viewer::overviewVoxelBudget(limits));
    const std::vector<lod::ZoomStage> stages =
        viewer::zoomStagesFor(*z.explorer, z.mediumLevel, std::max(1, viewPixels));
    if (stages.size() < 2) {
      throw InputError("zoom swap: " + z.name + " is too small to have coarser levels");
    }
    z.swap = std::make_unique<viewer::ZoomSwap>(*app().context, *z.explorer, stages);
    z.swap->keepLevel(0, z.whole);
    z.swap->setLabel(z.name);
    z.shownName = v.volumeName();
    zoomView() = std::move(z);
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
    if (!zoomActive()) return;
    const ZoomView& z = zoomView();
    const viewer::ZoomSwap& zs = *z.swap;
    viewer::Viewer& v = theViewer();
    j["active"] = true;
    j["name"] = z.name;
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
    if (const auto& b = zs.shownBox()) {
      j["block"] = {{"begin", {b->begin.x, b->begin.y, b->begin.z}},
                    {"end", {b->end.x, b->end.y, b->end.z}}};
    } else {
      j["block"] = nullptr;
    }
    j["voxels_read"] = zs.voxelsRead();
    j["whole_voxels"] = z.whole->voxelCount();
    j["medium_level"] = z.mediumLevel;
  });
  scratch() = j.dump();
  return scratch().c_str();
}

}  // extern "C"
