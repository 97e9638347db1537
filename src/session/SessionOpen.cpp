// The session's opening of named volumes: files, folders, stores (folder or
// URL), generated volumes, regions of them and pyramids to explore, and its
// headless device. Native only: the page hands its volumes over in memory
// (Session::setVolume) and fetches stores itself.
#include <cstdio>
#include <filesystem>

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
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/session/Session.h"

namespace tessera::session {

namespace {

// A time series the view plays in core: a 4-D file, or a store with a t
// axis whose level 0 fits a quarter of the host budget (a larger store is
// explored streamed, at the time point asked for).
bool playsInCore(const std::string& spec) {
  if (!isZarrStore(spec)) return timePointCount(spec) > 1;
  const ZarrStore store(openZarrStorage(spec));
  return store.timePoints() > 1 &&
         store.finestLevelWithin(HostBudget::global().limitBytes() / 4) == 0;
}

bool streamsBricks(const std::string& layoutWish) {
  return layoutWish != "auto" && layout::LayoutRegistry::global().find(layoutWish).streamsBricks;
}

// A store's t axis the view plays over bricks: asked for (a layout that
// streams bricks), or level 0 beyond what playsInCore holds.
bool playsOverBricks(const std::string& spec, const Settings& s) {
  if (!isZarrStore(spec)) return false;
  const ZarrStore store(openZarrStorage(spec));
  return store.timePoints() > 1 &&
         (streamsBricks(s.layout) ||
          store.finestLevelWithin(HostBudget::global().limitBytes() / 4) != 0);
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
  if (s.layout != "auto" || o.hostVoxels || s.labels) return nullptr;
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
    resident_.reset();
    region_.reset();
    series_.reset();
    streamedSeries_.reset();
    seriesWindow_.reset();
    timePoint_ = 0;
    streamed_ = std::move(pyramid);
    exploration_.reset();
    name_ = spec;
    applyVolumeSettings();  // the streamed view, through the window asked for
    return;
  }
  setVolume(
      readVolume(spec,
                 {.dicomSeries = options.series, .time = options.time, .channel = options.channel}),
      spec);
}

void Session::openInView(const std::string& spec, const OpenOptions& options) {
  viewer::Viewer& v = view();
  if (playsOverBricks(spec, settings_)) {
    openStreamedSeriesInView(spec, options);
    return;
  }
  // A time series is shown one time point at a time, each in core.
  if (playsInCore(spec)) {
    openSeries(spec, options);
    return;
  }
  const VolumePyramid pyramid = openVolumePyramid(
      spec, {.series = options.series, .time = options.time, .channel = options.channel});
  auto explore = std::make_unique<Exploration>(
      pyramid.source, viewer::regionBudgetBytes(v.limits()),
      viewer::overviewVoxelBudget(v.limits()), std::filesystem::path(spec).filename().string());
  // A copy: the exploration keeps its overview to come back to.
  v.setVolume(Volume(*explore->overview()), explore->overviewName());
  settings_ = currentSettings();  // the view's new window is the volume's own
  settings_.window.reset();
  const bool tfChanged = applyModalityDefault(v.volume());
  // The overview has the pyramid's window whether the volume came with one
  // or not: a voxel of level 0 tells (read only where a default applies).
  if (tfChanged && !v.volume().modality().empty()) {
    ownWindow_ = pyramid.source->readBox(0, {glm::ivec3(0), glm::ivec3(1)}).hasWindow();
  }
  showDefaultInView(tfChanged);
  series_.reset();
  streamedSeries_.reset();
  if (streamedFrames_) streamedFrames_->close();
  seriesWindow_.reset();
  timePoint_ = 0;
  inCore_.reset();
  resident_.reset();
  region_.reset();
  streamed_ = pyramid.source;
  streamedView_ = std::make_unique<lod::MultiresVolumeSource>(streamed_);
  exploration_ = std::move(explore);
  closeChannelView();
  name_ = spec;
}

void Session::openSeries(const std::string& spec, const OpenOptions& options) {
  // Streamed for run() and render(); the view draws in-core time points.
  if (!view_ && isZarrStore(spec) && streamsBricks(settings_.layout)) {
    openStreamedSeries(spec, options);
    return;
  }
  const int count = timePointCount(spec);
  if (count < 2) {
    throw InputError(
        spec + ": one time point, not a time series (a 4-D NIfTI or a store with a t axis is)");
  }
  const int channel = options.channel;
  openSeries(
      count, [spec, channel](int t) { return readTimePoint(spec, t, channel); }, spec,
      options.time);
}

// A named file, like the volumes above (the web build has the page's own:
// frontends/web/src/WebSessionOverlay.cpp).
void Session::openOverlay(const std::string& spec, const OverlayOptions& options) {
  setOverlay(session::openOverlay(spec, options, overlayAnatomy()));
}

}  // namespace tessera::session
