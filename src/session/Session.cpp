#include "tessera/session/Session.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/io/ZarrStore.h"
#include "tessera/layout/LayoutRegistry.h"
#include "tessera/layout/Planner.h"
#include "tessera/lod/MultiresVolumeSource.h"
#include "tessera/lod/ProceduralMultiresSource.h"
#include "tessera/lod/ZarrMultiresSource.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/LabelTable.h"
#include "tessera/render/TechniqueRegistry.h"

namespace tessera::session {

namespace {

const nlohmann::json kNoRegion;

bool streamsBricks(const std::string& layoutWish) {
  return layoutWish != "auto" && layout::LayoutRegistry::global().find(layoutWish).streamsBricks;
}

// With layout auto a store streams when the planner, given its finest level
// as a streamed shape and the technique's own units and bytes (what
// uploadVolume will ask it), rejects every in-core layout under the profile
// (its textures or its host budget; the plan's reason says which) and picks
// one that streams; a store that fits keeps the in-core path, and so does a
// technique with its own storage.
bool plannerStreams(const Settings& s, const gpu::DeviceSession& device,
                    const lod::MultiresSource& store) {
  const render::TechniqueEntry& entry = render::TechniqueRegistry::global().find(s.technique);
  const render::TechniqueRequirements r =
      entry.requirements(device.limits, store.shape().dims(), s.techniqueOptions({512, 512}));
  if (!r.ownStorage.empty()) return false;
  layout::PlanRequest request;
  request.reservedUnits = r.textureUnits;
  request.reservedBytes = r.bytes;
  request.streamed = true;
  const std::string chosen =
      layout::planLayout(store.shape(), device.limits, request).layout.layout;
  return layout::LayoutRegistry::global().find(chosen).streamsBricks;
}

// A volume read brick by brick instead of whole: a generated head:WxHxD, or
// an OME-Zarr store (folder or URL) with a streaming layout asked for, or
// with layout auto when its finest level does not fit in core. Null
// otherwise.
std::shared_ptr<const lod::MultiresSource> streamedSource(const std::string& spec,
                                                          const OpenOptions& o, const Settings& s,
                                                          const gpu::DeviceSession& device) {
  if (lod::ProceduralMultiresSource::isSpec(spec)) {
    return std::make_shared<lod::ProceduralMultiresSource>(spec);
  }
  if (!isZarrStore(spec)) return nullptr;
  const ZarrSelection zarr{.time = o.time, .channel = o.channel};
  if (streamsBricks(s.layout)) return lod::ZarrMultiresSource::open(spec, zarr);
  if (s.layout != "auto" || o.hostVoxels || s.window || s.labels) return nullptr;
  auto store = lod::ZarrMultiresSource::open(spec, zarr);
  if (!plannerStreams(s, device, *store)) return nullptr;
  return store;
}

// The region's box of its level, read with readBox (a store reads only the
// chunks it touches), placed where it lies in the full volume; its window
// is the full volume's so that it is coloured as in the overview.
Volume readRegion(const std::string& spec, const OpenOptions& o, nlohmann::json& report) {
  const VolumePyramid pyramid =
      openVolumePyramid(spec, {.series = o.series, .time = o.time, .channel = o.channel});
  const lod::MultiresSource& source = *pyramid.source;
  const int level = parseLevel(o.level, source.levelCount(), spec);
  const lod::LevelInfo info = source.levelInfo(level);
  std::string clamped;
  const lod::VoxelBox box = parseRegion(o.region, info.dims, &clamped);
  if (!clamped.empty()) std::fprintf(stderr, "tessera: note: --region %s\n", clamped.c_str());
  Volume region = source.readBox(level, box);
  region.setWindow(source.shape().window());
  report = {{"level", level},
            {"level_dims", {info.dims.x, info.dims.y, info.dims.z}},
            {"begin", {box.begin.x, box.begin.y, box.begin.z}},
            {"end", {box.end.x, box.end.y, box.end.z}},
            {"voxels_read", box.count()},
            {"level_voxels", lod::VoxelBox{glm::ivec3(0), info.dims}.count()}};
  if (!clamped.empty()) report["clamped"] = clamped;
  if (pyramid.storage) {
    report["chunks_read"] = pyramid.storage->chunksRead();
    report["chunk_bytes_read"] = pyramid.storage->chunkBytesRead();
    report["chunks_touched"] = chunksTouched(box, info.chunk, info.dims);
    report["chunks_in_level"] =
        chunksTouched(lod::VoxelBox{glm::ivec3(0), info.dims}, info.chunk, info.dims);
  }
  return region;
}

}  // namespace

Session::Session(const std::string& profile) : device_(gpu::openDevice(profile)) {
  // The planner weighs a streamed source's in-core read against the budget
  // the reader obeys: the profile's, or lower (TESSERA_HOST_BUDGET_MB, half
  // the physical memory).
  device_.limits.hostBudget = HostBudget::global().limitBytes();
}

Session::Session(gpu::DeviceSession device) : device_(std::move(device)) {}

Session::~Session() = default;

viewer::Viewer& Session::view() {
  if (view_) return *view_;
  view_ = std::make_unique<viewer::Viewer>(*device_.context, device_.profile);
  if (inCore_) showInView();
  applyToView();
  return *view_;
}

// The in-core volume into the view, shared: the view's window and label
// preparation are the session's volume's.
void Session::showInView() {
  view_->setVolume(inCore_->level(glm::ivec3(1)), name_);
}

// The settings into the view. Its camera keeps the radius and the frame it
// got from framing the volume; the window applies to a volume it shows.
void Session::applyToView() {
  viewer::Viewer& v = *view_;
  if (v.technique() != settings_.technique) v.setTechnique(settings_.technique);
  v.settings() = settings_.render;
  if (!v.hasVolume()) {
    v.tfEditor().setTransferFunction(settings_.tf);
    return;
  }
  if (settings_.labels) {
    if (!v.labelsOn()) v.setLabelsDefault();
  } else {
    if (v.labelsOn()) v.clearLabels();
    v.tfEditor().setTransferFunction(settings_.tf);
  }
  applyCameraToView();
  if (settings_.window) v.setWindow(*settings_.window);
}

void Session::applyCameraToView() {
  Camera& c = view_->camera();
  c.azimuthDeg = settings_.camera.azimuthDeg;
  c.elevationDeg = settings_.camera.elevationDeg;
  c.zoom = settings_.camera.zoom;
  c.fovYDeg = settings_.camera.fovYDeg;
  c.projection = settings_.camera.projection;
  c.target = settings_.camera.target;
}

Settings Session::currentSettings() const {
  Settings s = settings_;
  if (!view_) return s;
  viewer::Viewer& v = *view_;
  s.technique = v.technique();
  s.render = v.settings();
  s.labels = v.labelsOn();
  if (!s.labels) s.tf = v.tfEditor().transferFunction();
  const Camera& c = v.camera();
  s.camera.azimuthDeg = c.azimuthDeg;
  s.camera.elevationDeg = c.elevationDeg;
  s.camera.zoom = c.zoom;
  s.camera.fovYDeg = c.fovYDeg;
  s.camera.projection = c.projection;
  s.camera.target = c.target;
  if (v.hasVolume()) s.window = v.window();
  return s;
}

void Session::openInView(const std::string& spec, const OpenOptions& options) {
  viewer::Viewer& v = view();
  const VolumePyramid pyramid = openVolumePyramid(
      spec, {.series = options.series, .time = options.time, .channel = options.channel});
  auto explore = std::make_unique<Exploration>(
      pyramid.source, viewer::regionBudgetBytes(v.limits()),
      viewer::overviewVoxelBudget(v.limits()), std::filesystem::path(spec).filename().string());
  // A copy: the exploration keeps its overview to come back to.
  v.setVolume(Volume(*explore->overview()), explore->overviewName());
  settings_ = currentSettings();  // the view's new window is the volume's own
  settings_.window.reset();
  inCore_.reset();
  region_.reset();
  streamed_ = pyramid.source;
  streamedView_ = std::make_unique<lod::MultiresVolumeSource>(streamed_);
  exploration_ = std::move(explore);
  name_ = spec;
}

void Session::open(const std::string& spec, const OpenOptions& options) {
  settings_.validate();
  if (!options.region.empty()) {
    auto report = std::make_unique<nlohmann::json>();
    Volume region = readRegion(spec, options, *report);
    setVolume(std::move(region), spec);
    region_ = std::move(report);
    return;
  }
  if (options.level != "native") {
    throw InputError("--level " + options.level + " applies to --region (and to `tessera slice`)");
  }
  if (auto pyramid = streamedSource(spec, options, settings_, device_)) {
    inCore_.reset();
    region_.reset();
    streamed_ = std::move(pyramid);
    streamedView_ = std::make_unique<lod::MultiresVolumeSource>(streamed_);
    exploration_.reset();
    name_ = spec;
    return;
  }
  setVolume(
      readVolume(spec,
                 {.dicomSeries = options.series, .time = options.time, .channel = options.channel}),
      spec);
}

void Session::setVolume(Volume volume, const std::string& name) {
  setVolume(std::make_shared<Volume>(std::move(volume)), name);
}

void Session::setVolume(std::shared_ptr<Volume> volume, const std::string& name) {
  if (!volume) throw InputError("setVolume: no volume");
  auto next = std::make_shared<lod::InCoreVolumeSource>(std::move(volume));
  if (view_) {
    // The view's look carries over to the new volume, except its window and
    // labels, which are the new volume's own (viewer::Viewer::setVolume).
    view_->setVolume(next->level(glm::ivec3(1)), name);  // on error the old volume stays
    settings_ = currentSettings();
    settings_.window.reset();
  }
  streamed_.reset();
  streamedView_.reset();
  region_.reset();
  inCore_ = std::move(next);
  exploration_.reset();
  name_ = name;
  applyVolumeSettings();
}

Exploration& Session::exploration() {
  if (exploration_) return *exploration_;
  if (!hasVolume()) throw InputError("exploring: no volume is open");
  const gpu::DeviceLimits& limits = device_.limits;
  const std::uint64_t regionBytes = viewer::regionBudgetBytes(limits);
  exploration_ =
      streamed_ ? std::make_unique<Exploration>(streamed_, regionBytes,
                                                viewer::overviewVoxelBudget(limits), name_)
                : std::make_unique<Exploration>(inCore_->level(glm::ivec3(1)), regionBytes, name_);
  return *exploration_;
}

// The settings that change the in-core voxels' meaning: the window (raw
// values mapped to the TF) and a label volume's preparation.
void Session::applyVolumeSettings() {
  if (!inCore_) return;
  Volume& v = inCore_->volume();
  if (settings_.window) v.setWindow(*settings_.window);
  if (settings_.labels) render::prepareLabelVolume(v);
}

const Volume& Session::shape() const {
  if (!hasVolume()) throw InputError("the session has no volume: open one first");
  return source().shape();
}

const Volume& Session::volume() const {
  if (!inCore_) {
    throw InputError(hasVolume() ? name_ + " is streamed, not held in memory"
                                 : "the session has no volume: open one first");
  }
  return inCore_->volume();
}

Exploration& Session::explore(std::shared_ptr<const lod::MultiresSource> source,
                              std::uint64_t overviewVoxels, const std::string& label) {
  exploration_ = std::make_unique<Exploration>(
      std::move(source), viewer::regionBudgetBytes(device_.limits), overviewVoxels, label);
  return *exploration_;
}

const nlohmann::json& Session::regionReport() const {
  return region_ ? *region_ : kNoRegion;
}

const lod::VolumeSource& Session::source() const {
  if (streamedView_) return *streamedView_;
  if (!inCore_) throw InputError("the session has no volume: open one first");
  return *inCore_;
}

void Session::setSettings(Settings settings) {
  settings.validate();
  settings_ = std::move(settings);
  applyVolumeSettings();
  if (view_) applyToView();
}

RenderRequest Session::request(int width, int height) const {
  RenderRequest r;
  r.settings = settings_;
  r.width = width;
  r.height = height;
  return r;
}

RenderResult Session::run(const RenderRequest& request) {
  return runRender(device_, source(), request);
}

Image Session::render(int width, int height) {
  return run(request(width, height)).first;
}

Image Session::renderReference(int width, int height) {
  settings_.validate();
  Camera camera = settings_.camera;
  const Volume& v = volume();
  camera.frame(v);
  return tessera::renderReference(v, settings_.tf, camera, settings_.render, width, height);
}

nlohmann::json Session::state() const {
  nlohmann::json volume = nullptr;
  if (hasVolume()) {
    const Volume& s = shape();
    volume = {
        {"name", name_}, {"dims", {s.dims().x, s.dims().y, s.dims().z}}, {"streamed", streamed()}};
  }
  return {{"version", kSettingsVersion},
          {"volume", volume},
          {"settings", currentSettings().toJson()},
          {"exploration", exploration_ ? exploration_->state() : nlohmann::json(nullptr)}};
}

void Session::restore(const nlohmann::json& state) {
  if (!state.is_object() || !state.contains("settings")) {
    throw InputError("session state: expected {\"version\", \"volume\", \"settings\"}");
  }
  setSettings(Settings::fromJson(state["settings"]));
  if (!state.contains("exploration") || state["exploration"].is_null()) return;
  Exploration& e = exploration();
  const std::optional<ExploreStep> step = e.restore(state["exploration"]);
  if (!view_) return;
  if (step) {
    e.show(*view_, *step);
  } else if (e.overview() && e.mode() != ExploreMode::Overview) {
    e.showOverview(*view_, Follow::Keep);
  }
  applyCameraToView();  // the camera the state was saved with, on what it showed
}

void Session::saveState(const std::string& path) const {
  const std::filesystem::path p(path);
  std::error_code ec;
  if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path(), ec);
  std::ofstream out(p);
  out << state().dump(2) << "\n";
  out.close();
  if (!out) throw InputError(path + ": cannot write the session state: " + std::strerror(errno));
}

void Session::loadState(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot read the session state: " + std::strerror(errno));
  nlohmann::json state;
  try {
    state = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path + ": not a session state (not JSON: " + e.what() + ")");
  }
  try {
    restore(state);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
}

}  // namespace tessera::session
