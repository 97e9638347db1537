#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "app/ClippingOptions.h"
#include "app/Commands.h"
#include "app/HybridJob.h"
#include "app/RenderJob.h"
#include "app/SamplingOptions.h"
#include "app/ShadingOptions.h"
#include "app/VolumePyramid.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/core/Timing.h"
#include "tessera/io/HttpStorage.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/io/ZarrCachedStorage.h"
#include "tessera/io/ZarrStore.h"
#include "tessera/layout/FccLayout.h"
#include "tessera/layout/LayoutRegistry.h"
#include "tessera/layout/Planner.h"
#include "tessera/lod/InCoreVolumeSource.h"
#include "tessera/lod/MultiresVolumeSource.h"
#include "tessera/lod/ProceduralMultiresSource.h"
#include "tessera/lod/ZarrMultiresSource.h"
#include "tessera/render/LabelTable.h"
#include "tessera/render/TechniqueRegistry.h"

namespace tessera::app {

namespace {

struct RenderOptions {
  std::string file;
  std::string series;  // DICOM Series Instance UID
  int time = 0;        // OME-Zarr time point and channel
  int channel = 0;
  std::string tf = "mr-default";
  std::string size = "512x512";
  double azimuth = 0.0;
  double elevation = 0.0;
  double zoom = 1.0;
  double fov = 30.0;
  bool ortho = false;
  std::string mode = "composite";
  SamplingOptions sampling;
  int maxSteps = 4096;
  double opacityScale = 1.0;
  double ert = 0.99;
  bool jitter = false;
  std::vector<double> window;
  std::vector<double> background{0.0, 0.0, 0.0};
  std::string out = "out/render.png";
  bool reference = false;
  std::string referenceOut;
  double referenceStep = 0.0;
  int repeat = 1;
  double rotate = 10.0;
  int skipBlock = 8;
  int lut = 4096;
  std::string technique = "raycast";
  int slices = 0;
  std::string classify = "post";
  std::string profile = "native";
  std::string layout = "auto";
  std::string lattice = "cartesian";  // or fcc (FccLayout.h)
  std::string density;                // with --lattice fcc: same (default) or half
  bool json = false;
  // Hybrid low/high-resolution rendering with overlays (HybridJob.h).
  std::string overlays;
  std::string overlayOpacity = "alpha";
  std::string offscreen;
  std::string roi;
  // --region and --level: render only a box of one level, read with readBox.
  std::string region;
  std::string level = "native";
  ShadingOptions shading;
  ClippingOptions clipping;
  // --labels [TABLE]: a label volume through a categorical table.
  std::string labels;
  CLI::Option* labelsOption = nullptr;
  bool labelVolume() const { return labelsOption != nullptr && labelsOption->count() > 0; }
};

std::string describeStep(double step) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", step);
  return buf;
}

nlohmann::json numberOrNull(std::optional<double> v) {
  if (!v) return nullptr;
  if (std::isinf(*v)) return 999.0;  // identical images; JSON has no infinity
  return *v;
}

// --lattice and --density as a layout wish: the FCC lattice is a layout
// (layout/FccLayout.h: "fcc" at the same sample count, "fcc-half").
std::string latticeLayout(const RenderOptions& o) {
  if (o.lattice == "cartesian") {
    if (!o.density.empty()) throw InputError("--density applies to --lattice fcc only");
    return o.layout;
  }
  if (o.lattice != "fcc") {
    throw InputError("--lattice '" + o.lattice + "': expected cartesian or fcc");
  }
  if (o.layout != "auto") {
    throw InputError("--layout " + o.layout +
                     " does not combine with --lattice fcc: the lattice is stored in the fcc "
                     "layout");
  }
  return layout::FccLayout::layoutName(
      lattice::parseFccDensity(o.density.empty() ? "same" : o.density));
}

// The FCC lattice lives in a layout: a technique with its own storage
// (slice2d's slice stacks) cannot render it.
void checkSamplesLayout(const RenderOptions& o, const DeviceSession& device,
                        const lod::InCoreVolumeSource& source, const RenderRequest& req) {
  const render::TechniqueEntry& entry = render::TechniqueRegistry::global().find(o.technique);
  const render::TechniqueRequirements r =
      entry.requirements(device.limits, source.volume().dims(), req.techniqueOptions());
  if (!r.ownStorage.empty()) {
    throw InputError(
        "--lattice fcc needs a technique that samples the layout (e.g. raycast or "
        "slice3d); " +
        o.technique + " keeps " + r.ownStorage);
  }
}

// The camera, settings and technique the options ask for.
RenderRequest requestFrom(const RenderOptions& o) {
  RenderRequest req;
  parseSize(o.size, req.width, req.height);
  req.camera.azimuthDeg = o.azimuth;
  req.camera.elevationDeg = o.elevation;
  if (!(o.zoom > 0.0)) throw InputError("--zoom must be > 0");
  req.camera.zoom = o.zoom;
  if (!(o.fov > 0.0 && o.fov < 180.0)) throw InputError("--fov must be in (0, 180) degrees");
  req.camera.fovYDeg = o.fov;
  req.camera.projection = o.ortho ? Projection::Orthographic : Projection::Perspective;
  if (o.mode == "composite")
    req.settings.mode = RenderMode::Composite;
  else if (o.mode == "mip")
    req.settings.mode = RenderMode::Mip;
  else if (o.mode == "minip")
    req.settings.mode = RenderMode::MinIp;
  else if (o.mode == "average")
    req.settings.mode = RenderMode::Average;
  else
    throw InputError("--mode '" + o.mode + "': expected composite, mip, minip or average");
  applySampling(o.sampling, req.settings);
  req.settings.maxSteps = o.maxSteps;
  req.settings.opacityScale = o.opacityScale;
  req.settings.ertThreshold = o.ert;
  req.settings.jitter = o.jitter;
  req.settings.shading = shadingFrom(o.shading);
  req.settings.clipping = clippingFrom(o.clipping);
  if (o.labelVolume()) {
    render::applyLabelSettings(req.settings);
    req.lutSize = render::kLabelLutSize;
  }
  if (o.background.size() != 3) throw InputError("--background takes three numbers R G B in [0,1]");
  req.settings.background = glm::dvec4(o.background[0], o.background[1], o.background[2], 1.0);
  req.repeat = o.repeat;
  req.rotateDeg = o.repeat > 1 ? o.rotate : 0.0;
  if (o.referenceStep < 0.0 || !std::isfinite(o.referenceStep)) {
    throw InputError("--reference-step must be a positive number of voxels");
  }
  req.referenceStep = o.referenceStep;
  req.reference = o.reference || !o.referenceOut.empty() || o.referenceStep > 0.0;
  // Checked before the volume is read, so that a typo fails at once.
  if (!render::TechniqueRegistry::global().contains(o.technique)) {
    throw InputError("--technique '" + o.technique + "': expected " +
                     render::TechniqueRegistry::global().choices());
  }
  req.technique = o.technique;
  req.skipBlock = o.skipBlock;
  req.gradient = o.shading.gradient;
  req.lutSize = o.labelVolume() ? render::kLabelLutSize : o.lut;
  req.slices = o.slices;
  req.classify = o.classify;
  req.layout = latticeLayout(o);
  return req;
}

// Options that need the voxels in host memory (a window or label table
// applied to them, the hybrid compositor, the CPU reference, the FCC
// resampling): with these a store is read in core, at the finest level that
// fits the host budget.
bool needsInCore(const RenderOptions& o) {
  return o.labelVolume() || !o.window.empty() || !o.overlays.empty() || !o.offscreen.empty() ||
         !o.roi.empty() || o.reference || !o.referenceOut.empty() || o.referenceStep > 0.0 ||
         o.lattice != "cartesian";
}

// With --layout auto a store streams when the planner, given its finest
// level as a streamed shape and the technique's own units and bytes (what
// uploadVolume will ask it), rejects every in-core layout under the profile
// (its textures or its host budget; the plan's reason says which) and picks
// bricks; a store that fits keeps the in-core path, and so does a technique
// with its own storage.
bool plannerStreams(const RenderRequest& req, const DeviceSession& device,
                    const lod::MultiresSource& store) {
  const render::TechniqueEntry& entry = render::TechniqueRegistry::global().find(req.technique);
  const render::TechniqueRequirements r =
      entry.requirements(device.limits, store.shape().dims(), req.techniqueOptions());
  if (!r.ownStorage.empty()) return false;
  layout::PlanRequest request;
  request.reservedUnits = r.textureUnits;
  request.reservedBytes = r.bytes;
  request.streamed = true;
  return layout::planLayout(store.shape(), device.limits, request).layout.layout == "bricks";
}

// A volume read brick by brick instead of whole: a generated head:WxHxD, an
// OME-Zarr store (folder or URL) with --layout bricks, or with --layout auto
// when its finest level does not fit in core. Null otherwise.
std::shared_ptr<const lod::MultiresSource> streamedSource(const RenderOptions& o,
                                                          const RenderRequest& req,
                                                          const DeviceSession& device,
                                                          const std::string& spec) {
  if (lod::ProceduralMultiresSource::isSpec(spec)) {
    return std::make_shared<lod::ProceduralMultiresSource>(spec);
  }
  if (!isZarrStore(spec)) return nullptr;
  if (o.layout == "bricks") {
    return lod::ZarrMultiresSource::open(spec, {.time = o.time, .channel = o.channel});
  }
  if (o.layout != "auto" || needsInCore(o)) return nullptr;
  auto store = lod::ZarrMultiresSource::open(spec, {.time = o.time, .channel = o.channel});
  if (!plannerStreams(req, device, *store)) return nullptr;
  return store;
}

// --region: the box of the level, read with readBox (a store reads only the
// chunks it touches), placed where it lies in the full volume; its window is
// the full volume's so that it is coloured as in the overview.
Volume readRegion(const RenderOptions& o, const std::string& spec, nlohmann::json& report) {
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

// The volume (or its --region), with the window the options ask for.
lod::InCoreVolumeSource loadVolume(const RenderOptions& o, const std::string& spec,
                                   nlohmann::json& regionReport) {
  Volume volume =
      o.region.empty()
          ? readVolume(spec, {.dicomSeries = o.series, .time = o.time, .channel = o.channel})
          : readRegion(o, spec, regionReport);
  if (!o.window.empty()) {
    if (o.window.size() != 2) throw InputError("--window takes two numbers MIN MAX");
    volume.setWindow({o.window[0], o.window[1]});
  }
  if (o.labelVolume()) render::prepareLabelVolume(volume);
  return lod::InCoreVolumeSource(std::move(volume));
}

// --overlays, --offscreen or --roi: the hybrid compositor's run.
void runHybridCommand(const RenderOptions& o, DeviceSession& device,
                      const lod::InCoreVolumeSource& source, const TransferFunction& tf,
                      const RenderRequest& req, const std::string& spec,
                      render::OverlayOpacity overlayOpacity) {
  HybridRequest h;
  h.overlays = render::OverlayOptions::parse(o.overlays);
  if (!o.roi.empty()) h.overlays.setRoiVoxels(o.roi, source.volume());
  h.hybrid.offscreen = render::OffscreenSize::parse(o.offscreen.empty() ? "full" : o.offscreen);
  h.hybrid.opacity = overlayOpacity;
  const HybridResult hr = runHybridRender(device, source, tf, req, h);
  hr.image.writePng(o.out);
  if (hr.groundTruth && !o.referenceOut.empty()) hr.groundTruth->writePng(o.referenceOut);
  printHybridResult(hr, req, h, device, spec, o.out, o.json);
}

struct RenderTimes {
  double loadMs = 0.0;
  double totalMs = 0.0;
};

// What a store streamed over HTTP(S) cost: bodies received (all attempts).
struct HttpFetch {
  std::uint64_t bytes = 0;
  std::uint64_t requests = 0;
  std::uint64_t retries = 0;
};

std::optional<HttpFetch> httpFetch(const lod::MultiresSource& source) {
  const auto* zarr = dynamic_cast<const lod::ZarrMultiresSource*>(&source);
  const ZarrStorage* storage = zarr ? &zarr->store().storage() : nullptr;
  if (const auto* cached = dynamic_cast<const CachedStorage*>(storage)) storage = &cached->inner();
  const auto* http = dynamic_cast<const HttpStorage*>(storage);
  if (!http) return std::nullopt;
  return HttpFetch{http->bytesFetched(), http->requests(), http->retries()};
}

void printRenderJson(const RenderOptions& o, const RenderRequest& req, const RenderResult& r,
                     const DeviceSession& device, const TransferFunction& tf,
                     const std::string& spec, RenderTimes times, const nlohmann::json& region,
                     std::optional<HttpFetch> fetch = std::nullopt) {
  const gpu::GlContext& context = *device.context;
  nlohmann::json j;
  if (!region.is_null()) j["region"] = region;
  j["file"] = spec;
  j["out"] = o.out;
  j["width"] = req.width;
  j["height"] = req.height;
  j["frames"] = r.frameMs.size();
  j["ms_median"] = r.median();
  j["ms_min"] = r.min();
  j["ms_max"] = r.max();
  j["frame_ms"] = r.frameMs;
  j["psnr_db"] = numberOrNull(r.psnrDb);
  j["ssim"] = numberOrNull(r.ssim);
  if (r.referenceImage) j["reference_ms"] = r.referenceMs;
  j["texture_bytes"] = r.textureBytes;
  j["volume_texture_bytes"] = r.volumeTextureBytes;
  j["gl_renderer"] = context.caps().renderer;
  j["gl_version"] = context.caps().version;
  j["egl_platform"] = context.platform();
  j["layout"] = r.layout;
  j["lattice"] = o.lattice;
  j["profile"] = device.profile.name;
  j["api"] = gpu::apiLevelName(device.limits.api);
  j["plan_reason"] = r.plan.reason;
  j["downsample"] = {r.plan.downsample.x, r.plan.downsample.y, r.plan.downsample.z};
  j["rendered_dims"] = {r.renderedDims.x, r.renderedDims.y, r.renderedDims.z};
  j["texture_budget"] = device.limits.textureBudget;
  j["load_ms"] = times.loadMs;
  j["prepare_ms"] = r.prepareMs;
  j["occupied_block_fraction"] = r.occupiedBlockFraction;
  j["total_ms"] = times.totalMs;
  if (r.bricks) {
    const BricksRun& b = *r.bricks;
    j["bricks"] = {{"refine_frames", b.refineFrames},
                   {"first_frame_ms", b.firstFrameMs},
                   {"complete_ms", b.completeMs},
                   {"complete", b.complete},
                   {"failing", b.failing},
                   {"wanted_per_level", b.wantedPerLevel},
                   {"cells_per_level", b.cellsPerLevel},
                   {"rotating_levels", b.rotatingLevels},
                   {"slots", b.slots},
                   {"bytes_read", b.bytesRead},
                   {"bricks_read", b.bricksRead},
                   {"read_errors", b.readErrors},
                   {"cache_peak_bytes", b.cachePeakBytes}};
  }
  if (fetch) {
    j["http"] = {{"bytes_fetched", fetch->bytes},
                 {"requests", fetch->requests},
                 {"retries", fetch->retries}};
  }
  j["mode"] = o.mode;
  j["technique"] = o.technique;
  j["step_voxels"] = req.settings.stepVoxels;
  j["preintegrate"] = r.preintegrated;
  j["adaptive"] = r.adaptive;
  if (r.adaptive) {
    j["adaptive_tolerance"] = adaptiveTolerance(req.settings);
    j["adaptive_max"] = req.settings.sampling.maxMultiplier;
  }
  if (r.preintegrated) {
    j["preintegration_build_ms"] = r.preintegrationBuildMs;
    j["preintegration_upload_ms"] = r.preintegrationUploadMs;
  }
  if (r.referenceImage) {
    j["reference_step"] = r.referenceStep;
    j["reference_is_twin"] = req.referenceStep <= 0.0;
  }
  if (r.samplesPerRay > 0.0) j["samples_per_ray"] = r.samplesPerRay;
  j["shade"] = o.shading.shade;
  j["tf"] = tf.name;
  std::printf("%s\n", j.dump(2).c_str());
}

void printRenderText(const RenderOptions& o, const RenderRequest& req, const RenderResult& r,
                     const DeviceSession& device, const Volume& volume, const std::string& spec,
                     RenderTimes times, std::optional<HttpFetch> fetch = std::nullopt) {
  const gpu::GlContext& context = *device.context;
  std::printf("wrote %s (%dx%d) in %.0f ms total\n", o.out.c_str(), req.width, req.height,
              times.totalMs);
  std::printf("volume   %s: %dx%dx%d %s, loaded in %.0f ms\n", spec.c_str(), volume.dims().x,
              volume.dims().y, volume.dims().z, std::string(scalarTypeName(volume.type())).c_str(),
              times.loadMs);
  std::printf("gpu      %s (%s, EGL %s); %s context, GLSL ES %s\n", context.caps().renderer.c_str(),
              context.caps().version.c_str(), context.platform().c_str(),
              device.limits.api == gpu::ApiLevel::Gles2 ? "ES 2.0" : "ES 3.0",
              device.limits.api == gpu::ApiLevel::Gles2 ? "1.00" : "3.00");
  std::printf("profile  %s (%s)\n", device.profile.name.c_str(), device.profile.note.c_str());
  std::printf("layout   %s: %s\n", r.layout.c_str(), r.layoutReason.c_str());
  if (o.technique == "raycast") {
    RenderSettings effective = req.settings;
    effective.sampling.preintegrate = r.preintegrated;
    effective.sampling.preintegrateLitOnly = false;
    effective.sampling.adaptive = r.adaptive;
    std::string line = describeSampling(effective);
    if (r.preintegrated) {
      char buf[96];
      std::snprintf(buf, sizeof buf, " (table rebuilt in %.2f ms + %.2f ms upload)",
                    r.preintegrationBuildMs, r.preintegrationUploadMs);
      line += buf;
    }
    std::printf("sampling %s%s\n", line.c_str(),
                o.sampling.stepGiven() ? "" : "; the default (docs/sampling.md)");
  }
  if (req.settings.shading.enabled && !r.gradient.empty()) {
    std::printf("gradient %s\n", r.gradient.c_str());
  }
  if (!r.planNote.empty()) std::printf("note     %s\n", r.planNote.c_str());
  std::printf("textures %s on the GPU (%llu bytes)%s\n", formatBytes(r.textureBytes).c_str(),
              static_cast<unsigned long long>(r.textureBytes),
              device.limits.textureBudget
                  ? (", budget " + formatBytes(device.limits.textureBudget)).c_str()
                  : "");
  if (r.frameMs.size() == 1) {
    std::printf("render   %.1f ms (after %.0f ms of shader compile and set-up)\n", r.frameMs[0],
                r.prepareMs);
  } else {
    std::printf("render   %zu frames, rotating %g deg: median %.1f ms, min %.1f, max %.1f\n",
                r.frameMs.size(), o.rotate, r.median(), r.min(), r.max());
  }
  if (r.bricks) {
    const BricksRun& b = *r.bricks;
    std::string wanted, cells;
    for (std::size_t l = 0; l < b.wantedPerLevel.size(); ++l) {
      if (b.wantedPerLevel[l])
        wanted += " L" + std::to_string(l) + ":" + std::to_string(b.wantedPerLevel[l]);
    }
    for (std::size_t l = 0; l < b.cellsPerLevel.size(); ++l) {
      if (!b.cellsPerLevel[l]) continue;
      cells += (l + 1 == b.cellsPerLevel.size() ? " empty:" : " L" + std::to_string(l) + ":") +
               std::to_string(b.cellsPerLevel[l]);
    }
    std::printf(
        "bricks   frame 0 %s after %d frames: first image %.0f ms, refined %.0f ms; "
        "%llu bricks read (%s), %llu read errors, %d left coarser (failing), host "
        "cache peak %s, %d atlas slots\n",
        b.complete ? "refined" : "stopped refining", b.refineFrames, b.firstFrameMs, b.completeMs,
        static_cast<unsigned long long>(b.bricksRead), formatBytes(b.bytesRead).c_str(),
        static_cast<unsigned long long>(b.readErrors), b.failing,
        formatBytes(b.cachePeakBytes).c_str(), b.slots);
    std::printf("levels   bricks wanted:%s; page-table cells:%s\n", wanted.c_str(), cells.c_str());
  }
  if (fetch) {
    std::printf("http     fetched %s in %llu requests (%llu retries)\n",
                formatBytes(fetch->bytes).c_str(), static_cast<unsigned long long>(fetch->requests),
                static_cast<unsigned long long>(fetch->retries));
  }
  if (r.psnrDb) {
    const std::string what =
        req.referenceStep > 0.0
            ? "fine reference (step " + describeStep(r.referenceStep) + " voxel, every sample)"
            : "reference (the render's own samples)";
    std::printf("reference %s: %.0f ms on the CPU; PSNR %.2f dB, SSIM %.5f\n", what.c_str(),
                r.referenceMs, *r.psnrDb, *r.ssim);
    if (r.samplesPerRay > 0.0) {
      std::printf("samples  %.1f per ray that meets the volume\n", r.samplesPerRay);
    }
  }
}

// The default output lies in out/, which a fresh checkout lacks: the folders an
// output path names are created before the frame is rendered, so a path that
// cannot be written fails before the render's work instead of after it.
void createParentFolders(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (parent.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(parent, ec);
  if (ec) {
    throw InputError(path + ": cannot create its folder " + parent.string() + ": " + ec.message());
  }
}

void runRenderCommand(const RenderOptions& o) {
  const auto tStart = std::chrono::steady_clock::now();
  createParentFolders(o.out);
  if (!o.referenceOut.empty()) createParentFolders(o.referenceOut);
  const RenderRequest req = requestFrom(o);
  const std::string spec = o.file.empty() ? defaultVolumeSpec() : o.file;
  TransferFunction tf =
      o.labelVolume() ? TransferFunction() : TransferFunction::fromPresetOrFile(o.tf);
  // The profile first: it sets the host budget the reader must respect.
  DeviceSession device = openDevice(o.profile);
  // The planner weighs a streamed source's in-core read against the budget
  // the reader obeys: the profile's, or lower (TESSERA_HOST_BUDGET_MB, half
  // the physical memory).
  device.limits.hostBudget = HostBudget::global().limitBytes();
  RenderTimes times;
  const auto tLoad = std::chrono::steady_clock::now();
  // --region reads its one box in core instead.
  if (auto pyramid = o.region.empty() ? streamedSource(o, req, device, spec) : nullptr) {
    const lod::MultiresVolumeSource streamed(pyramid);  // read brick by brick, never whole
    times.loadMs = msSince(tLoad);
    const RenderResult r = runRender(device, streamed, tf, req);
    r.first.writePng(o.out);
    times.totalMs = msSince(tStart);
    if (o.json) {
      printRenderJson(o, req, r, device, tf, spec, times, nullptr, httpFetch(*pyramid));
    } else {
      printRenderText(o, req, r, device, streamed.shape(), spec, times, httpFetch(*pyramid));
    }
    return;
  }
  if (o.region.empty() && o.level != "native") {
    throw InputError("--level " + o.level + " applies to --region (and to `tessera slice`)");
  }
  nlohmann::json regionReport;
  const lod::InCoreVolumeSource source = loadVolume(o, spec, regionReport);
  if (o.labelVolume()) {
    const render::LabelTable table = o.labels.empty()
                                         ? render::LabelTable::defaultFor(source.volume())
                                         : render::LabelTable::load(o.labels);
    tf = table.toTransferFunction();
  }
  times.loadMs = msSince(tLoad);

  if (o.lattice == "fcc") checkSamplesLayout(o, device, source, req);
  // Checked even when nothing uses it, so that a typo is not silently ignored.
  const render::OverlayOpacity overlayOpacity = render::parseOverlayOpacity(o.overlayOpacity);
  if (!o.overlays.empty() || !o.offscreen.empty() || !o.roi.empty()) {
    runHybridCommand(o, device, source, tf, req, spec, overlayOpacity);
    return;
  }
  const RenderResult r = runRender(device, source, tf, req);
  r.first.writePng(o.out);
  if (r.referenceImage && !o.referenceOut.empty()) r.referenceImage->writePng(o.referenceOut);
  times.totalMs = msSince(tStart);
  if (o.json) {
    printRenderJson(o, req, r, device, tf, spec, times, regionReport);
  } else {
    printRenderText(o, req, r, device, source.volume(), spec, times);
    if (!regionReport.is_null()) std::printf("region   %s\n", regionReport.dump().c_str());
  }
}

}  // namespace

void addRenderCommand(CLI::App& app) {
  auto o = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand(
      "render", "Render a volume headless to a PNG (GPU ray caster through EGL)");
  cmd->add_option("file", o->file, kVolumeHelp);
  addSeriesOption(cmd, o->series);
  addTimeChannelOptions(cmd, o->time, o->channel);
  cmd->add_option(
         "--tf", o->tf,
         "Transfer function: preset (grey, mr-default, ct-bone, ct-muscle, bench) or FILE.json")
      ->capture_default_str();
  cmd->add_option("--size", o->size, "Image size WIDTHxHEIGHT")->capture_default_str();
  cmd->add_option("--azimuth", o->azimuth,
                  "Camera azimuth in degrees about the patient's superior axis (0: looking at the "
                  "face from anterior, 90: from the patient's right), for every storage order")
      ->capture_default_str();
  cmd->add_option("--elevation", o->elevation,
                  "Camera elevation in degrees (90: looking down from superior)")
      ->capture_default_str();
  cmd->add_option("--zoom", o->zoom, "Zoom factor (>1 magnifies)")->capture_default_str();
  cmd->add_option("--fov", o->fov, "Vertical field of view in degrees (perspective)")
      ->capture_default_str();
  cmd->add_flag("--ortho", o->ortho, "Orthographic projection");
  cmd->add_option("--mode", o->mode,
                  "composite, mip (maximum), minip (minimum) or average (mean of the ray's "
                  "samples): the projections show the TF colour of their value; minip and "
                  "average by raycast only")
      ->capture_default_str();
  addSamplingOptions(cmd, o->sampling);
  cmd->add_option("--max-steps", o->maxSteps, "Maximum samples per ray")->capture_default_str();
  cmd->add_option("--opacity-scale", o->opacityScale, "Global opacity scale")
      ->capture_default_str();
  cmd->add_option("--ert", o->ert, "Early ray termination threshold (>= 1 disables)")
      ->capture_default_str();
  cmd->add_flag("--jitter", o->jitter, "Jitter the first sample per pixel");
  addShadingOptions(cmd, o->shading);
  addClippingOptions(cmd, o->clipping);
  o->labelsOption =
      cmd->add_option("--labels", o->labels,
                      "Render a label volume (atlas, 8-bit integer labels): nearest-neighbour "
                      "sampling and a categorical colour table instead of --tf. TABLE (optional): "
                      "JSON {\"labels\": [{\"value\", \"name\", \"color\": [r,g,b] 0..1, "
                      "\"opacity\", \"visible\"}]} or a label text file (ITK-SNAP, FreeSurfer "
                      "LUT, or mricron's IDX NAME); labels it does not name are hidden. Without "
                      "TABLE: a default palette for every label present")
          ->expected(0, 1);
  cmd->add_option("--window", o->window,
                  "Value window MIN MAX (raw values); default: the value range")
      ->expected(2);
  cmd->add_option("--background", o->background, "Background colour R G B in [0,1]")->expected(3);
  cmd->add_option("--out", o->out, "Output PNG")->capture_default_str();
  cmd->add_flag("--reference", o->reference,
                "Also render with the CPU reference and print PSNR/SSIM");
  cmd->add_option("--reference-out", o->referenceOut,
                  "Write the reference image to this PNG (implies --reference)");
  cmd->add_option("--reference-step", o->referenceStep,
                  "Judge quality against a fine reference instead: the CPU reference at this "
                  "step in voxels (e.g. 0.25), every sample, post-classified (implies "
                  "--reference; without it the reference takes the render's own samples)");
  cmd->add_option("--repeat", o->repeat, "Render N frames, rotating the camera, and report timings")
      ->capture_default_str();
  cmd->add_option("--rotate", o->rotate, "Azimuth step in degrees between repeated frames")
      ->capture_default_str();
  cmd->add_option("--skip-block", o->skipBlock,
                  "Empty-space skipping block size in voxels (0 = off)")
      ->capture_default_str();
  cmd->add_option("--lut", o->lut, "Transfer-function table entries (256 or 4096)")
      ->capture_default_str();
  cmd->add_option("--technique", o->technique, render::TechniqueRegistry::global().describe())
      ->capture_default_str();
  cmd->add_option("--slices", o->slices,
                  "Slices: slice3d over the volume diagonal (0 = from --step), slice2d drawn "
                  "per stack (0 = every voxel plane)")
      ->capture_default_str();
  cmd->add_option("--classify", o->classify,
                  "slice2d classification: pre (CPU RGBA), palette (index + palette) or post (LUT)")
      ->capture_default_str();
  cmd->add_option("--profile", o->profile,
                  "Device profile to obey (tessera profiles lists them) or FILE.json")
      ->capture_default_str();
  cmd->add_option("--layout", o->layout,
                  "Volume storage: " + layout::LayoutRegistry::global().choices() +
                      " (auto: the planner chooses)")
      ->capture_default_str();
  cmd->add_option("--lattice", o->lattice,
                  "Sample lattice: cartesian (the volume's grid, trilinear) or fcc (resampled "
                  "onto the face-centred cubic lattice with a cubic B-spline and "
                  "quasi-interpolation, reconstructed with the six-direction box spline; needs "
                  "an ES 3 profile; --reference then renders the box spline on the CPU)")
      ->capture_default_str();
  cmd->add_option("--density", o->density,
                  "With --lattice fcc: same (as many lattice points as voxels, default) or half "
                  "(every voxel with an even index sum, no interpolation)");
  cmd->add_flag("--json", o->json, "Print one JSON object instead of text");
  cmd->add_option("--overlays", o->overlays,
                  "Lines drawn at full resolution with the volume: box,axes,roi (any subset); "
                  "with --reference the ground truth stops each ray at its line");
  cmd->add_option("--overlay-opacity", o->overlayOpacity,
                  "How lines behind/inside the volume are attenuated: alpha (target alpha), "
                  "two-pass (renders over black and white), luma-avg, luma-601")
      ->capture_default_str();
  cmd->add_option("--offscreen", o->offscreen,
                  "Render the volume at WxH (e.g. 128x128, 256x512) or a factor (e.g. 0.25) and "
                  "upscale it bilinearly (hybrid rendering; default with --overlays: full)");
  cmd->add_option("--roi", o->roi,
                  "Region of interest x0:x1,y0:y1,z0:z1 in voxels for the roi overlay "
                  "(implies it)");
  cmd->add_option("--region", o->region,
                  "Render only the voxels x0:x1,y0:y1,z0:z1 (end exclusive) of --level, read as "
                  "one box (a store reads only the chunks it touches, never the whole level), "
                  "placed where it lies in the volume; the camera frames it. Ends past the "
                  "level are clamped (with a note)");
  cmd->add_option("--level", o->level, "With --region: pyramid level, native (0, the finest) or N")
      ->capture_default_str();
  cmd->callback([o] { runRenderCommand(*o); });
}

}  // namespace tessera::app
