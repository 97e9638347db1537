#include "tessera/session/Session.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/lod/MultiresVolumeSource.h"
#include "tessera/lod/WindowedSource.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/FusionTexture.h"
#include "tessera/render/LabelTable.h"
#include "tessera/session/ModalityDefault.h"

namespace tessera::session {

namespace {

const nlohmann::json kNoRegion;

}  // namespace

namespace {

// What the upload and the technique depend on: every setting but the camera
// and the TF (set on each frame), and the image size.
std::string residentKey(const RenderRequest& r) {
  nlohmann::json j = r.settings.toJson();
  j.erase("camera");
  j.erase("tf");
  j["size"] = {r.width, r.height};
  return j.dump();
}

}  // namespace

Session::Session(gpu::DeviceSession device) : device_(std::move(device)) {}

// The view's and the exploration's GL objects are released on this
// session's context, whichever session drew last on this thread.
Session::~Session() {
  try {
    makeCurrent();
  } catch (const Error&) {
    // The context is gone: its objects went with it.
  }
}

void Session::makeCurrent() {
  if (lost_) {
    throw GpuError("the GPU context was lost: nothing is drawn until it is restored");
  }
  if (device_.context) device_.context->makeCurrent();
}

viewer::Viewer& Session::view() {
  makeCurrent();
  if (view_) return *view_;
  view_ = std::make_unique<viewer::Viewer>(*device_.context, device_.profile);
  if (overlay_) view_->setFusion(overlay_->fused);
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

void Session::setVolume(Volume volume, const std::string& name) {
  setVolume(std::make_shared<Volume>(std::move(volume)), name);
}

void Session::openSeries(int count, TimeSeries::Reader read, const std::string& name, int time,
                         TimeSeries::Reading reading) {
  if (count < 2) throw InputError(name + ": one time point, not a time series");
  if (time < 0 || time >= count) {
    throw InputError(name + ": time point " + std::to_string(time) + " asked for, the series has " +
                     std::to_string(count) + " (0.." + std::to_string(count - 1) + ")");
  }
  auto first = std::make_shared<Volume>(read(time));
  const int keep =
      TimeSeries::keepWithin(HostBudget::global().limitBytes() / 4, first->byteSize(), count);
  auto series = std::make_unique<TimeSeries>(count, std::move(read), keep, reading);
  setVolume(first, name);
  // Every time point in the first one's window, unless the settings say one.
  seriesWindow_ = settings_.window ? *settings_.window : first->window();
  series_ = std::move(series);
  timePoint_ = time;
  series_->want(timePoint_);  // reads ahead from here
}

bool Session::showTimePoint(int t) {
  if (channelView_ && channelView_->series()) {
    if (!channelView_->showTime(t)) return false;
    timePoint_ = t;
    return true;
  }
  if (streamedSeries_) return showStreamedTimePoint(t);
  if (!series_) throw InputError("no time series is open");
  std::shared_ptr<Volume> v = series_->want(t);
  if (!v) return false;
  if (inCore_ && &inCore_->volume() == v.get()) return true;
  v->setWindow(seriesWindow_.value_or(v->window()));
  auto next = std::make_shared<lod::InCoreVolumeSource>(v);
  if (view_) {
    makeCurrent();
    // The same scene at another time: the camera and the look stay.
    const Camera camera = view_->camera();
    const Settings look = currentSettings();
    view_->setVolume(next->level(glm::ivec3(1)), name_);
    view_->camera() = camera;
    view_->setWindow(v->window());
    settings_ = look;
  }
  // The slice views' crosshair, region side and picked box carry over to
  // the next time point, and a region or grid block is shown again from it.
  std::optional<nlohmann::json> explored;
  if (exploration_) explored = exploration_->state();
  inCore_ = std::move(next);
  exploration_.reset();
  again_.reset();
  timePoint_ = t;
  applyVolumeSettings();
  if (explored) showExplorationAgain(*explored);
  return true;
}

void Session::showExplorationAgain(const nlohmann::json& state) {
  Exploration& e = exploration();
  const std::optional<ExploreStep> step = e.restore(state);
  if (!step || !view_) return;
  // The same box of this time point; the camera stays where the user left it.
  const Camera camera = view_->camera();
  const ValueRange window = view_->window();
  e.showIn(*view_, e.read(*step), {step->box, step->mode, Follow::Keep});
  view_->setWindow(window);
  view_->camera() = camera;
}

void Session::waitTimePoint(int t) {
  if (!series()) throw InputError("no time series is open");
  series()->wait(t);
  showTimePoint(t);
}

int Session::stepPlayback(double nowMs, bool shownComplete) {
  TimeSeries* const series = this->series();
  const int shownNow = timePoint();
  if (!series) return shownNow;
  // A time point is shown when its full frame is: while the view refines
  // it (progressive strips), the next one waits.
  if (view_ && view_->refining()) return timePoint();
  // Over bricks the same: the front end's frame of the time point shown
  // must have been drawn with every brick its view wants (unless the view
  // shows a region or grid block of it instead, which refines as above).
  if (streamedSeries_ && streamedFrames_ && !boxInView() &&
      !streamedFrames_->shownComplete(timePoint_)) {
    return timePoint();
  }
  const int count = series->count();
  const int next = (shownNow + 1) % count;
  // The window of reads starts at the time point shown (and so holds it
  // and the next): asking for the next one instead would let the shown one
  // go and read it again, over and over.
  series->want(shownNow);
  // Without a reading thread, one time point ahead is read per frame.
  series->pump();
  bool ready = series->isRead(next);
  // A time point that cannot be read stops playback with the reader's
  // message, rather than holding the one shown for ever. A series the
  // front end draws with a region or grid block in the view waits for that
  // box's chunks of the next time point too.
  try {
    if (!ready) series->rethrowFailure(next);
    ready = ready && drawnBoxArrived(next);
  } catch (const std::exception& e) {
    playback_.pause();
    throw InputError(name_ + ": playback stopped: time point " + std::to_string(next) +
                     " could not be read: " + e.what());
  }
  const int shown = playback_.step(nowMs, shownNow, count, ready && shownComplete);
  if (shown != shownNow) showTimePoint(shown);
  return timePoint();
}

void Session::setVolume(std::shared_ptr<Volume> volume, const std::string& name) {
  if (!volume) throw InputError("setVolume: no volume");
  series_.reset();
  streamedSeries_.reset();
  if (streamedFrames_) streamedFrames_->close();
  seriesWindow_.reset();
  timePoint_ = 0;
  auto next = std::make_shared<lod::InCoreVolumeSource>(std::move(volume));
  if (view_) {
    makeCurrent();
    // The view's look carries over to the new volume, except its window and
    // labels, which are the new volume's own (viewer::Viewer::setVolume).
    view_->setVolume(next->level(glm::ivec3(1)), name);  // on error the old volume stays
    settings_ = currentSettings();
    settings_.window.reset();
  }
  streamed_.reset();
  streamedView_.reset();
  region_.reset();
  resident_.reset();
  inCore_ = std::move(next);
  exploration_.reset();
  again_.reset();
  closeChannelView();
  name_ = name;
  const bool tfChanged = applyModalityDefault(inCore_->volume());
  applyVolumeSettings();
  if (view_) showDefaultInView(tfChanged);
}

// Another volume replaces the one whose channels were shown together: the
// view shows the new one (a front end opens its channels again if it has
// several).
void Session::closeChannelView() {
  if (channelView_ && channelView_->isOpen()) channelView_->close();
}

// The modality default's TF and window into the view (its upload's copy of
// the window and the editor's histogram).
void Session::showDefaultInView(bool tfChanged) {
  viewer::Viewer& v = *view_;
  if (tfChanged) v.tfEditor().setTransferFunction(settings_.tf);
  if (ownWindow_ || settings_.window || !v.hasVolume()) return;
  if (auto w = clinicalPresetWindow(settings_.tf, v.volume())) v.setWindow(*w);
}

// A TF the user did not name becomes the modality's default; the default
// of a volume opened before gives way to the front end's own TF again when
// this one has none.
bool Session::applyModalityDefault(const Volume& v) {
  ownWindow_ = v.hasWindow();
  defaultNote_.clear();
  if (!settings_.tfIsDefault) defaultNote_ = presetNote(settings_.tf, v);
  if (!settings_.tfIsDefault || settings_.labels) return false;
  const std::optional<ModalityDefault> chosen = modalityDefault(v);
  if (!chosen) {
    if (!tfBeforeDefault_) return false;
    settings_.tf = *tfBeforeDefault_;
    tfBeforeDefault_.reset();
    return true;
  }
  if (!tfBeforeDefault_) tfBeforeDefault_ = settings_.tf;
  settings_.tf = chosen->tf;
  defaultNote_ = chosen->note;
  return true;
}

Exploration& Session::exploration() {
  makeCurrent();
  if (exploration_) return *exploration_;
  if (!hasVolume()) throw InputError("exploring: no volume is open");
  const gpu::DeviceLimits& limits = device_.limits;
  const std::uint64_t regionBytes = viewer::regionBudgetBytes(limits);
  exploration_ =
      streamed_ ? std::make_unique<Exploration>(streamed_, regionBytes, explorationOverviewVoxels(),
                                                name_)
                : std::make_unique<Exploration>(inCore_->level(glm::ivec3(1)), regionBytes, name_);
  return *exploration_;
}

// The settings that change the voxels' meaning: the window (raw values
// mapped to the TF) and a label volume's preparation. A streamed volume is
// seen through the window (lod::WindowedSource), so that its bricks are
// classified and drawn with it.
void Session::applyVolumeSettings() {
  if (streamed_) {
    std::shared_ptr<const lod::MultiresSource> seen = streamed_;
    if (settings_.window)
      seen = std::make_shared<lod::WindowedSource>(streamed_, *settings_.window);
    streamedView_ = std::make_unique<lod::MultiresVolumeSource>(std::move(seen));
  }
  if (!inCore_) return;
  Volume& v = inCore_->volume();
  if (settings_.window) {
    v.setWindow(*settings_.window);
  } else if (!ownWindow_ && !settings_.labels) {
    if (auto w = clinicalPresetWindow(settings_.tf, v)) v.setWindow(*w);
  }
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
  makeCurrent();
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

void Session::setOverlay(Overlay overlay) {
  // An interactive view refuses it up front (ES 2: no 3D textures) rather
  // than showing the anatomy alone; run() checks its own frames.
  if (view_ && overlay.fused) render::FusionTexture::checkDevice(device_.limits, *overlay.fused);
  overlay_ = std::make_unique<Overlay>(std::move(overlay));
  if (view_) view_->setFusion(overlay_->fused);
}

void Session::restyleOpenOverlay(const OverlayOptions& options) {
  if (!overlay_) throw InputError("no overlay is open");
  setOverlay(restyleOverlay(*overlay_, options, overlayAnatomy()));
}

void Session::clearOverlay() {
  overlay_.reset();
  if (view_) view_->setFusion(nullptr);
}

ProbeResult Session::probe(glm::dvec3 worldMm) const {
  if (drawn_) return session::probe(*drawn_, overlay_.get(), worldMm);  // the page's store
  // Explored in the view (openInView): its overview holds the values.
  if (!inCore_ && exploration_)
    return session::probe(*exploration_->overview(), overlay_.get(), worldMm);
  if (streamed_) return session::probe(*streamed_, overlay_.get(), worldMm);
  return session::probe(volume(), overlay_.get(), worldMm);
}

RenderRequest Session::request(int width, int height) const {
  RenderRequest r;
  r.settings = settings_;
  if (overlay_) r.fusion = overlay_->fused;
  r.width = width;
  r.height = height;
  return r;
}

RenderResult Session::run(const RenderRequest& request) {
  makeCurrent();
  if (overlay_ && !request.fusion) {
    RenderRequest withOverlay = request;
    withOverlay.fusion = overlay_->fused;
    return runRender(device_, source(), std::move(withOverlay));
  }
  return runRender(device_, source(), request);
}

Image Session::render(int width, int height) {
  if (!inCore_) return run(request(width, height)).first;
  makeCurrent();
  RenderRequest req = request(width, height);
  checkImageSize(width, height);
  if (req.fusion) render::FusionTexture::checkDevice(device_.limits, *req.fusion);
  req.settings.validate();
  const std::string key = residentKey(req);
  if (!resident_ || resident_->source != inCore_ || resident_->key != key) {
    resident_.reset();  // its textures go before the next ones are made
    auto next = std::make_unique<Resident>();
    next->technique =
        render::createTechnique(req.settings.technique, *device_.context, device_.limits, *inCore_,
                                req.techniqueOptions(), req.settings.layout);
    next->source = inCore_;
    next->key = key;
    resident_ = std::move(next);
  }
  render::Technique& technique = *resident_->technique.technique;
  prepareFrame(technique, *resident_->technique.upload.volume, req);
  technique.render(req.settings.camera, req.settings.render, width, height, 0.0);
  return technique.readImage();
}

Image Session::renderReference(int width, int height) {
  checkImageSize(width, height);
  settings_.validate();
  Camera camera = settings_.camera;
  const Volume& v = volume();
  camera.frame(v);
  if (overlay_) {
    RenderSettings fused = settings_.render;
    applyFusionSettings(fused);
    const FusionTwin twin{*overlay_->fused, fusedFromAnatomy(v, *overlay_->fused->volume)};
    return tessera::renderReference(v, settings_.tf, camera, fused, width, height, 0, nullptr,
                                    nullptr, nullptr, &twin);
  }
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
          {"exploration", exploration_ ? exploration_->state() : nlohmann::json(nullptr)},
          {"overlay", overlayState(overlay_.get())}};
}

void Session::restore(const nlohmann::json& state) {
  if (!state.is_object() || !state.contains("settings")) {
    throw InputError("session state: expected {\"version\", \"volume\", \"settings\"}");
  }
  setSettings(Settings::fromJson(state["settings"]));
  restoreOverlay(state);
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

nlohmann::json readStateFile(const std::string& path) {
  if (std::filesystem::is_directory(path)) throw InputError(path + ": a folder, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open: " + std::strerror(errno));
  nlohmann::json state;
  try {
    state = nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(path + ": not JSON (syntax error at byte " + std::to_string(e.byte) + ")");
  } catch (const nlohmann::json::exception& e) {  // out_of_range for 1e999
    throw InputError(path + ": not JSON (" + e.what() + ")");
  }
  if (!state.is_object() || !state.contains("settings") || !state["settings"].is_object()) {
    throw InputError(path + ": expected a session state {\"version\", \"settings\": {...}}");
  }
  const nlohmann::json version = state.value("version", nlohmann::json());
  if (version != kSettingsVersion) {
    throw InputError(path + ": state version " + version.dump() + ", this Tessera reads " +
                     std::to_string(kSettingsVersion));
  }
  return state;
}

void Session::loadState(const std::string& path) {
  const nlohmann::json state = readStateFile(path);
  try {
    restore(state);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
}

}  // namespace tessera::session
