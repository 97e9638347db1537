// The session's view, volumes and settings (WebSession.h), and the one
// pointer that owns the session.
#include "WebSession.h"

#include <algorithm>
#include <optional>
#include <span>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "WebDicomStacks.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/DeviceSession.h"
#include "tessera/gpu/Draw.h"
#include "tessera/io/ByteSource.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/render/LabelTable.h"
#include "tessera/session/Settings.h"

namespace tessera::web {

namespace {

// The page's session: made by tessera_init, destroyed by tessera_dispose
// (or a later tessera_init on another canvas).
std::unique_ptr<WebSession> gSession;

// The page's default sampling: `tessera render`'s (defaultSampling()) without
// pre-integration. In browsers without a GPU (SwiftShader) the
// pre-integration table's filtered half-float fetch costs more than the
// fewer samples save: on ch2 at 512^2 the page took 1.4-2.0x longer per frame
// pre-integrated than with the adaptive steps alone, which keep 45-48 dB
// against the 0.25-voxel reference (docs/web-peers.md, "Sampling in the
// browser"). The page's "pre-integrated" control switches it on.
constexpr Sampling webDefaultSampling() {
  Sampling s = defaultSampling();
  s.preintegrate = false;
  return s;
}

}  // namespace

WebSession& session() {
  if (!gSession) throw GpuError("the viewer has no WebGL context yet (tessera_init)");
  return *gSession;
}

WebSession* sessionIfAny() {
  return gSession.get();
}

void startSession(const std::string& canvasSelector, int webglVersion) {
  // The previous session's GPU objects go with its context, before the new
  // context is made current.
  gSession.reset();
  gSession = std::make_unique<WebSession>(canvasSelector, webglVersion);
}

void endSession() {
  gSession.reset();
}

WebSession::WebSession(const std::string& canvasSelector, int webglVersion)
    : canvasSelector_(canvasSelector),
      context_(std::make_unique<gpu::WebGlContext>(canvasSelector, webglVersion)) {
  makeSession();
}

WebSession::~WebSession() {
  // GPU objects are deleted while their context is current.
  if (context_) context_->makeCurrent();
}

void WebSession::makeSession() {
  session_ = std::make_unique<session::Session>(
      gpu::borrowDevice(context(), gpu::DeviceProfile::find(context().platform())));
  session::Settings settings = session_->settings();
  settings.render.sampling = webDefaultSampling();
  session_->setSettings(std::move(settings));
  session_->view();  // the 3D view from the start (its TF editor, camera)
}

// The session keeps in host memory what it showed (Session::loseContext:
// the volume, settings, camera, the view's knobs, the exploration, overlay
// and channels) and makes its GPU side again on the new context
// (Session::restoreContext); the page's own parts are made again here: an
// open store's view (its chunks, metadata and levels kept), which then
// shows the region or grid block again (storeOpenStep). The old objects
// were the lost context's: deleting them only raised GL errors, cleared
// before the new context is used.
void WebSession::recoverContext() {
  zoomStop();
  std::optional<ZarrStoreView::Host> store;
  if (zarr_) store = zarr_->host();
  const int webglVersion = context_->webglVersion();
  zarr_.reset();
  session_->loseContext();
  context_.reset();
  context_ = std::make_unique<gpu::WebGlContext>(canvasSelector_, webglVersion);
  gpu::clearErrors();
  session_->restoreContext(
      gpu::borrowDevice(context(), gpu::DeviceProfile::find(context().platform())));
  refreshExtraLines();
  if (store) reopenStore(std::move(*store));
}

void WebSession::loadGenerated(const std::string& spec) {
  zoomForget();
  session_->setVolume(makeProcedural(spec), spec);
}

void WebSession::loadPickedFiles() {
  // Kept by the reader of a time series, which reads its time points from
  // these bytes as playback asks for them.
  struct HeldFiles {
    std::vector<PickedFile> picked;
    MemoryFiles files;
  };
  auto held = std::make_shared<HeldFiles>();
  held->picked = std::move(picked_);
  picked_.clear();
  for (const PickedFile& f : held->picked) {
    held->files.add(f.name, std::span<const std::byte>(
                                reinterpret_cast<const std::byte*>(f.bytes.get()), f.size));
  }
  const std::string name = volumeFileAmong(held->files.names());
  zoomForget();
  const std::unique_ptr<ByteSource> file = held->files.open(name);
  const int count = timePointCount(*file);
  if (count > 1) {
    session_->openSeries(
        count,
        [held, name](int t) { return readTimePoint(*held->files.open(name), held->files, t); },
        name);
    return;
  }
  session_->setVolume(readPickedVolume(*file, held->files), name);  // WebDicomStacks.h
}

double WebSession::renderFrame(int width, int height) {
  refreshExtraLines();
  return zoomOverview() ? zoomFrame(width, height) : viewer().render(width, height).ms;
}

// Keeps the projection.
void WebSession::setCamera(double azimuth, double elevation, double zoom) {
  Camera& c = viewer().camera();
  const Projection projection = c.projection;
  viewer().resetCamera();
  c.projection = projection;
  c.azimuthDeg = azimuth;
  c.elevationDeg = elevation;
  c.zoom = zoom;
}

void WebSession::setStep(double voxels) {
  session::checkRange("step", voxels, session::kStepRange, "voxels");
  viewer().settings().stepVoxels = voxels;
}

void WebSession::setLight(bool headlight, double ambient, double diffuse, double specular,
                          double shininess, const glm::dvec3& direction) {
  if (!headlight && glm::length(direction) < 1e-6) {
    throw InputError("the fixed light needs a direction");
  }
  Shading& s = viewer().settings().shading;
  s.headlight = headlight;
  s.ambient = std::clamp(ambient, 0.0, 1.0);
  s.diffuse = std::clamp(diffuse, 0.0, 1.0);
  s.specular = std::clamp(specular, 0.0, 1.0);
  s.shininess = std::clamp(shininess, 1.0, 256.0);
  if (!s.headlight) s.lightDirection = direction;
}

void WebSession::setGradientOpacity(bool on, double low, double high) {
  if (!(low >= 0.0 && high > low)) {
    throw InputError("gradient opacity: needs 0 <= low < high (got " + std::to_string(low) + ", " +
                     std::to_string(high) + ")");
  }
  Shading& s = viewer().settings().shading;
  s.gradientOpacity = on;
  s.gradientLow = low;
  s.gradientHigh = high;
}

void WebSession::setCrop(const glm::dvec3& lo, const glm::dvec3& hi) {
  for (int a = 0; a < 3; ++a) {
    if (!(lo[a] >= 0.0 && hi[a] <= 1.0 && lo[a] < hi[a])) {
      throw InputError(std::string("crop box: ") + "xyz"[a] + " must satisfy 0 <= min < max <= 1");
    }
  }
  viewer().settings().clipping.cropMin = lo;
  viewer().settings().clipping.cropMax = hi;
  refreshExtraLines();
}

// At `depth` x half the volume's diagonal from its centre towards the viewer.
void WebSession::setFollowingPlane(bool on, double depth) {
  viewer::Viewer& v = viewer();
  v.clipPlaneFollowsCamera = on;
  const double reach = v.hasVolume() ? 0.5 * glm::length(v.volume().extent()) : 0.0;
  v.followingPlaneDistance = std::clamp(depth, -1.0, 1.0) * reach;
}

// The table goes through render::LabelTable's parsers: JSON when it starts
// with '{', else a label text file (ITK-SNAP, FreeSurfer, mricron).
void WebSession::setLabels(bool on, const std::string& table, const std::string& name) {
  if (on) zoomStop();  // labels are not averaged into coarser levels
  viewer::Viewer& v = viewer();
  if (!on) {
    v.clearLabels();
    return;
  }
  if (table.empty()) {
    v.setLabelsDefault();
    return;
  }
  const auto first = table.find_first_not_of(" \t\r\n");
  const bool json = first != std::string::npos && table[first] == '{';
  v.setLabels(json ? render::LabelTable::fromJson(table, name)
                   : render::LabelTable::fromText(table, name));
}

// The region / grid boxes and the crop box are lines of the viewer composed
// with the volume by depth, like the bounding box and axes
// (render/HybridCompositor): hidden behind opaque tissue, faded behind
// translucent.
void WebSession::applyMarkBoxes() {
  viewer::Viewer& v = viewer();
  v.extraLines.clear();
  if (!v.hasVolume() || regionShown()) return;  // the region or block is the view itself
  // The zoom swap's levels span the whole volume (its block is the view).
  const Volume* whole = zoomOverview();
  if (whole && zoomBox()) return;
  const glm::ivec3 dims = whole ? whole->dims() : v.volume().dims();
  const glm::vec4 colours[2] = {{1.0f, 0.25f, 0.2f, 1.0f}, {0.25f, 0.85f, 0.95f, 1.0f}};
  for (int slot = 0; slot < 2; ++slot) {
    const MarkBox& m = marks_[slot];
    if (!m.box || m.dims != dims) continue;
    const auto lines = viewer::boxLines(*m.box, dims, v.volume().extent(), colours[slot]);
    v.extraLines.insert(v.extraLines.end(), lines.begin(), lines.end());
  }
}

void WebSession::refreshExtraLines() {
  applyMarkBoxes();
  viewer::Viewer& v = viewer();
  if (crop_.show && v.hasVolume()) {
    const auto lines = viewer::CropHandles::lines(v.settings().clipping, v.volume().extent(),
                                                  crop_.handles.dragging());
    v.extraLines.insert(v.extraLines.end(), lines.begin(), lines.end());
  }
}

void WebSession::setMarkBox(int slot, const lod::VoxelBox& box) {
  if (slot < 0 || slot > 1) throw InputError("mark box: slot must be 0 or 1");
  MarkBox& m = marks_[slot];
  if (glm::any(glm::lessThanEqual(box.end, box.begin)) || !viewer().hasVolume()) {
    m.box.reset();
    return;
  }
  m.dims = sliceShape().dims();
  m.box = lod::VoxelBox{glm::clamp(box.begin, glm::ivec3(0), m.dims),
                        glm::clamp(box.end, glm::ivec3(0), m.dims)};
}

void WebSession::restoreState(const std::string& json) {
  const nlohmann::json state = nlohmann::json::parse(json, nullptr, false);
  if (state.is_discarded()) throw InputError("session state: not JSON");
  if (storeOverview()) {
    // A store's region and grid blocks are fetched by the page first.
    throw InputError("session state: restoring is for a loaded file, not an open OME-Zarr store");
  }
  zoomStop();
  if (session_->hasVolume()) exploration();  // the page's exploration, for the state to fill
  session_->restore(state);
  refreshExtraLines();
}

const std::uint8_t* WebSession::readPixels(int width, int height) {
  pixels_.assign(static_cast<std::size_t>(width) * height * 4, 0);
  std::vector<std::uint8_t> rows(pixels_.size());
  gpu::bindFramebuffer(0, {0, 0, width, height});
  gpu::readPixelsRgba8({0, 0, width, height}, rows.data());
  const std::size_t stride = static_cast<std::size_t>(width) * 4;
  for (int y = 0; y < height; ++y) {
    std::copy_n(rows.data() + static_cast<std::size_t>(height - 1 - y) * stride, stride,
                pixels_.data() + static_cast<std::size_t>(y) * stride);
  }
  return pixels_.data();
}

}  // namespace tessera::web
