#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/ClippingOptions.h"
#include "cli/Commands.h"
#include "cli/FusionOptions.h"
#include "cli/HybridJob.h"
#include "cli/SamplingOptions.h"
#include "cli/ShadingOptions.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/core/Timing.h"
#include "tessera/io/HttpStorage.h"
#include "tessera/io/ZarrCachedStorage.h"
#include "tessera/io/ZarrChannels.h"
#include "tessera/io/ZarrStore.h"
#include "tessera/layout/FccLayout.h"
#include "tessera/layout/LayoutRegistry.h"
#include "tessera/lod/ZarrMultiresSource.h"
#include "tessera/render/LabelTable.h"
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/session/Session.h"

namespace tessera::app {

using gpu::DeviceSession;
using session::BricksRun;
using session::parseRenderMode;
using session::RenderRequest;
using session::RenderResult;
using session::Session;
using session::Settings;

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
  int referenceLevel = 0;
  CLI::Option* referenceLevelOption = nullptr;
  bool referenceLevelGiven() const {
    return referenceLevelOption != nullptr && referenceLevelOption->count() > 0;
  }
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
  // --state FILE: the settings to start from; --save-state FILE: where the
  // render's own go. `command`: which options the command line gave.
  std::string state;
  std::string saveState;
  const CLI::App* command = nullptr;
  // Several channels of a store together (docs/channels.md).
  std::string channels;
  std::string channelColors;
  std::string channelWindows;
  std::string channelMode;
  bool channelsRequested() const {
    return !channels.empty() || !channelColors.empty() || !channelWindows.empty() ||
           !channelMode.empty();
  }
  FusionOptions fusion;  // --overlay and its look (FusionOptions.h)
};

// Where each option that sets a setting lands in the settings' JSON
// (session::Settings::toJson): with --state, an option given on the command
// line replaces these keys of the file's settings, and the file keeps the
// rest.
const std::map<std::string, std::vector<std::string>>& settingKeys() {
  static const std::map<std::string, std::vector<std::string>> keys = {
      {"--tf", {"/tf"}},
      {"--azimuth", {"/camera/azimuth"}},
      {"--elevation", {"/camera/elevation"}},
      {"--zoom", {"/camera/zoom"}},
      {"--fov", {"/camera/fov"}},
      {"--ortho", {"/camera/projection"}},
      {"--mode", {"/mode"}},
      {"--step", {"/step"}},
      {"--preintegrate", {"/sampling/preintegrate"}},
      {"--adaptive", {"/sampling/adaptive"}},
      // Given, the tolerance holds for lit frames too (applySampling).
      {"--adaptive-tolerance", {"/sampling/tolerance", "/sampling/lit_tolerance"}},
      {"--adaptive-max", {"/sampling/max_multiplier"}},
      {"--adaptive-growth", {"/sampling/opacity_growth"}},
      {"--max-steps", {"/max_steps"}},
      {"--opacity-scale", {"/opacity_scale"}},
      {"--ert", {"/ert"}},
      {"--jitter", {"/jitter"}},
      {"--shade", {"/shading/enabled"}},
      {"--gradient", {"/gradient"}},
      {"--light", {"/shading/headlight", "/shading/light_direction"}},
      {"--gradient-opacity",
       {"/shading/gradient_opacity", "/shading/gradient_low", "/shading/gradient_high"}},
      {"--ambient", {"/shading/ambient"}},
      {"--diffuse", {"/shading/diffuse"}},
      {"--specular", {"/shading/specular"}},
      {"--shininess", {"/shading/shininess"}},
      {"--crop", {"/clipping/crop_min", "/clipping/crop_max"}},
      {"--clip", {"/clipping/planes"}},
      // The table's TF replaces the file's once the volume is read.
      {"--labels", {"/labels", "/lut", "/nearest"}},
      {"--window", {"/window"}},
      {"--background", {"/background"}},
      {"--skip-block", {"/skip_block"}},
      {"--lut", {"/lut"}},
      {"--technique", {"/technique"}},
      {"--slices", {"/slices"}},
      {"--classify", {"/classify"}},
      {"--layout", {"/layout"}},
      {"--lattice", {"/layout"}},
      {"--density", {"/layout"}},
  };
  return keys;
}

// The options that say what to read, how to run and what to write, not how
// to draw: --state leaves them as the command line has them.
const std::set<std::string>& runOptions() {
  static const std::set<std::string> names = {
      "file",          "--series",     "--time",          "--channel",        "--size",
      "--out",         "--reference",  "--reference-out", "--reference-step", "--reference-level",
      "--repeat",      "--rotate",     "--profile",       "--json",           "--overlays",
      "--offscreen",   "--roi",        "--region",        "--level",          "--line-attenuation",
      "--state",       "--save-state", "--channels",      "--channel-colors", "--channel-windows",
      "--channel-mode"};
  return names;
}

// Every option of `tessera render` is one or the other, so that --state
// cannot silently drop a new setting's option: checked when the command is
// built, which every run of the CLI does.
void checkOptionsClassified(const CLI::App& cmd) {
  for (const auto& [name, keys] : settingKeys()) {
    if (cmd.get_option_no_throw(name) == nullptr) {
      throw std::logic_error("tessera render: settingKeys() names " + name +
                             ", which is no option of the command");
    }
  }
  for (const CLI::Option* opt : cmd.get_options()) {
    if (opt == cmd.get_help_ptr() || opt == cmd.get_help_all_ptr()) continue;
    const std::string name = opt->get_name();
    if (!settingKeys().contains(name) && !runOptions().contains(name) &&
        !fusionOptionNames().contains(name)) {
      throw std::logic_error("tessera render: option " + name +
                             " is in neither settingKeys() nor runOptions() (RenderCommand.cpp)");
    }
  }
}

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
  const std::string lattices[] = {"cartesian", "fcc"};  // the option's words
  if (o.lattice == lattices[0]) {
    if (!o.density.empty()) throw InputError("--density applies to --lattice fcc only");
    return o.layout;
  }
  if (o.lattice != lattices[1]) {
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
void checkSamplesLayout(const RenderOptions& o, const DeviceSession& device, const Volume& volume,
                        const RenderRequest& req) {
  const render::TechniqueEntry& entry = render::TechniqueRegistry::global().find(o.technique);
  const render::TechniqueRequirements r =
      entry.requirements(device.limits, volume.dims(), req.techniqueOptions());
  if (!r.ownStorage.empty()) {
    throw InputError(
        "--lattice fcc needs a technique that samples the layout (e.g. raycast or "
        "slice3d); " +
        o.technique + " keeps " + r.ownStorage);
  }
}

// The camera, settings and technique the options ask for.
Settings settingsFrom(const RenderOptions& o) {
  Settings s;
  s.camera.azimuthDeg = o.azimuth;
  s.camera.elevationDeg = o.elevation;
  s.camera.zoom = o.zoom;
  s.camera.fovYDeg = o.fov;
  s.camera.projection = o.ortho ? Projection::Orthographic : Projection::Perspective;
  s.render.mode = parseRenderMode(o.mode);
  applySampling(o.sampling, s.render);
  s.render.maxSteps = o.maxSteps;
  s.render.opacityScale = o.opacityScale;
  s.render.ertThreshold = o.ert;
  s.render.jitter = o.jitter;
  s.render.shading = shadingFrom(o.shading);
  s.render.clipping = clippingFrom(o.clipping);
  if (o.background.size() != 3) throw InputError("--background takes three numbers R G B in [0,1]");
  s.render.background = glm::dvec4(o.background[0], o.background[1], o.background[2], 1.0);
  if (!o.window.empty()) {
    if (o.window.size() != 2) throw InputError("--window takes two numbers MIN MAX");
    s.window = ValueRange{o.window[0], o.window[1]};
  }
  s.labels = o.labelVolume();
  s.technique = o.technique;
  s.skipBlock = o.skipBlock;
  s.gradient = o.shading.gradient;
  s.lutSize = o.labelVolume() ? render::kLabelLutSize : o.lut;
  s.slices = o.slices;
  s.classify = o.classify;
  s.layout = latticeLayout(o);
  if (s.labels) render::applyLabelSettings(s.render);
  if (!s.labels) s.tf = TransferFunction::fromPresetOrFile(o.tf);
  // Without --tf the volume's modality picks the TF (session/ModalityDefault.h).
  s.tfIsDefault = o.command == nullptr || o.command->get_option("--tf")->count() == 0;
  s.validate();
  return s;
}

// The settings of a state file (what --save-state writes), as JSON, checked
// by the one settings type. InputError names the option, the file and the
// problem.
nlohmann::json readStateSettings(const std::string& path) {
  try {
    const nlohmann::json state = session::readStateFile(path);
    try {
      return Settings::fromJson(state["settings"]).toJson();
    } catch (const InputError& e) {
      throw InputError(path + ": " + e.what());
    }
  } catch (const InputError& e) {
    throw InputError("--state " + std::string(e.what()));
  }
}

// --state: the file's settings, with the keys that the options given on
// the command line set replaced by the options' values.
Settings stateWithOptions(const RenderOptions& o) {
  nlohmann::json merged = readStateSettings(o.state);
  const nlohmann::json given = settingsFrom(o).toJson();
  for (const auto& [option, keys] : settingKeys()) {
    if (o.command->get_option(option)->count() == 0) continue;
    for (const std::string& key : keys) {
      const nlohmann::json::json_pointer at(key);
      merged[at] = given.at(at);
    }
  }
  return Settings::fromJson(merged);
}

// The camera, settings and technique the options ask for (over the file of
// --state), checked by the session's one settings type before the volume is
// read, so that a typo fails at once.
RenderRequest requestFrom(const RenderOptions& o) {
  RenderRequest req;
  parseSize(o.size, req.width, req.height);
  req.settings = o.state.empty() ? settingsFrom(o) : stateWithOptions(o);
  req.repeat = o.repeat;
  if (req.repeat < 1) throw InputError("--repeat must be >= 1");
  req.rotateDeg = o.repeat > 1 ? o.rotate : 0.0;
  if (o.referenceStep < 0.0 || !std::isfinite(o.referenceStep)) {
    throw InputError("--reference-step must be a positive number of voxels");
  }
  req.referenceStep = o.referenceStep;
  req.reference =
      o.reference || !o.referenceOut.empty() || o.referenceStep > 0.0 || o.referenceLevelGiven();
  if (o.referenceLevelGiven()) req.referenceLevel = o.referenceLevel;
  return req;
}

// Options that need the voxels in host memory (the hybrid compositor, the
// CPU reference, the FCC resampling): with these a store is read in core,
// at the finest level that fits the host budget. A fused volume does not:
// it is fused into a streamed store's bricks too (docs/fusion.md).
bool needsHostVoxels(const RenderOptions& o) {
  return !o.overlays.empty() || !o.offscreen.empty() || !o.roi.empty() || o.reference ||
         !o.referenceOut.empty() || o.referenceStep > 0.0 || o.referenceLevelGiven() ||
         o.lattice != "cartesian";
}

// --overlays, --offscreen or --roi: the hybrid compositor's run.
void runHybridCommand(const RenderOptions& o, Session& session, const RenderRequest& req,
                      const std::string& spec, render::OverlayOpacity overlayOpacity) {
  HybridRequest h;
  h.overlays = render::OverlayOptions::parse(o.overlays);
  if (!o.roi.empty()) h.overlays.setRoiVoxels(o.roi, session.volume());
  h.hybrid.offscreen = render::OffscreenSize::parse(o.offscreen.empty() ? "full" : o.offscreen);
  h.hybrid.opacity = overlayOpacity;
  const HybridResult hr = runHybridRender(session.device(), session.source(), req, h);
  hr.image.writePng(o.out);
  if (hr.groundTruth && !o.referenceOut.empty()) hr.groundTruth->writePng(o.referenceOut);
  printHybridResult(hr, req, h, session.device(), spec, o.out, o.json);
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
                     const DeviceSession& device, const std::string& spec, RenderTimes times,
                     const nlohmann::json& region, std::optional<HttpFetch> fetch = std::nullopt) {
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
                   {"failed_reads", b.failedReads},
                   {"failed_read_count", b.failedReadCount},
                   {"cache_peak_bytes", b.cachePeakBytes}};
  }
  if (fetch) {
    j["http"] = {{"bytes_fetched", fetch->bytes},
                 {"requests", fetch->requests},
                 {"retries", fetch->retries}};
  }
  j["mode"] = std::string(renderModeToName(req.settings.render.mode));
  j["technique"] = req.settings.technique;
  j["step_voxels"] = req.settings.render.stepVoxels;
  j["preintegrate"] = r.preintegrated;
  j["adaptive"] = r.adaptive;
  if (r.adaptive) {
    j["adaptive_tolerance"] = adaptiveTolerance(req.settings.render);
    j["adaptive_max"] = req.settings.render.sampling.maxMultiplier;
  }
  if (r.preintegrated) {
    j["preintegration_build_ms"] = r.preintegrationBuildMs;
    j["preintegration_upload_ms"] = r.preintegrationUploadMs;
  }
  if (r.referenceImage) {
    j["reference_step"] = r.referenceStep;
    j["reference_is_twin"] = req.referenceStep <= 0.0;
  }
  if (r.referenceLevel) {
    j["reference_level"] = *r.referenceLevel;
    j["reference_level_dims"] = {r.referenceLevelDims.x, r.referenceLevelDims.y,
                                 r.referenceLevelDims.z};
    j["reference_level_mixed"] = r.referenceLevelMixed;
    j["reference_level_note"] = r.referenceLevelNote;
  }
  if (r.samplesPerRay > 0.0) j["samples_per_ray"] = r.samplesPerRay;
  j["shade"] = req.settings.render.shading.enabled;
  j["tf"] = req.settings.tf.name;
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
  if (render::TechniqueRegistry::global().find(req.settings.technique).honoursSampling) {
    RenderSettings effective = req.settings.render;
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
    std::printf(
        "sampling %s%s\n", line.c_str(),
        o.sampling.stepGiven() || !o.state.empty() ? "" : "; the default (docs/sampling.md)");
  }
  if (req.settings.render.shading.enabled && !r.gradient.empty()) {
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
    for (const std::string& e : b.failedReads) std::printf("failed   %s\n", e.c_str());
    if (b.failedReadCount > b.failedReads.size()) {
      std::printf("failed   ... and %zu more\n", b.failedReadCount - b.failedReads.size());
    }
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
    if (r.referenceLevel) {
      std::printf("ref level %d (%dx%dx%d): %s\n", *r.referenceLevel, r.referenceLevelDims.x,
                  r.referenceLevelDims.y, r.referenceLevelDims.z, r.referenceLevelNote.c_str());
    }
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

// Frame 0 of a streamed volume is the refined one unless bricks were given
// up (their reads kept failing) or refining stopped at its limit: the PNG
// and the report are written all the same, then the command ends with
// kExitIncomplete, naming what failed.
void checkRefined(const RenderOptions& o, const RenderResult& r) {
  if (!r.bricks || (r.bricks->complete && r.bricks->failing == 0)) return;
  const BricksRun& b = *r.bricks;
  std::string why = o.out;
  if (b.failing > 0) {
    why += " shows " + std::to_string(b.failing) +
           " bricks at a coarser level because their reads kept failing: ";
    for (std::size_t i = 0; i < b.failedReads.size(); ++i) {
      why += (i ? "; " : "") + b.failedReads[i];
    }
    if (b.failedReadCount > b.failedReads.size()) {
      why += " (and " + std::to_string(b.failedReadCount - b.failedReads.size()) + " more)";
    }
  }
  if (!b.complete) {
    char limit[160];
    std::snprintf(limit, sizeof limit,
                  "%srefining stopped at its limit (%d frames, %.0f s) with bricks still missing",
                  b.failing > 0 ? "; " : " is not refined: ", b.refineFrames,
                  b.completeMs / 1000.0);
    why += limit;
  }
  throw IncompleteOutput(why);
}

// --save-state: the session's state after the render (version, volume,
// settings), which --state reads back.
void saveState(const RenderOptions& o, const Session& session) {
  if (!o.saveState.empty()) session.saveState(o.saveState);
}

// --channels and the other --channel-* options: the store's channels in one
// frame (Session::renderChannels), with --reference the CPU reference's.
void runChannelsCommand(const RenderOptions& o, const std::string& spec) {
  RenderRequest req = requestFrom(o);
  session::ChannelSettings& c = req.settings.channels;
  c.enabled = true;
  if (!o.channels.empty()) c.indices = parseChannelList(o.channels);
  if (!o.channelColors.empty()) c.colors = session::parseChannelColors(o.channelColors);
  if (!o.channelWindows.empty()) c.windows = session::parseChannelWindows(o.channelWindows);
  if (!o.channelMode.empty()) c.mode = parseChannelMode(o.channelMode);
  Session session(o.profile);
  session.settings() = req.settings;
  const session::ChannelFrame f =
      session.renderChannels(spec, req.width, req.height, req.reference, o.time);
  f.image.writePng(o.out);
  if (f.reference && !o.referenceOut.empty()) f.reference->writePng(o.referenceOut);
  if (o.json) {
    nlohmann::json j = {{"file", spec},
                        {"out", o.out},
                        {"layout", f.layout},
                        {"channels", f.channels},
                        {"mode", channelModeName(c.mode)},
                        {"gpu_ms", f.gpuMs}};
    if (f.reference) {
      j["psnr_db"] = numberOrNull(f.psnr);
      j["reference_ms"] = f.referenceMs;
    }
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf("file     %s\nlayout   %s\nmode     %s\n", spec.c_str(), f.layout.c_str(),
              channelModeName(c.mode));
  for (std::size_t i = 0; i < f.channels.size(); ++i) {
    std::printf("channel  %s\n", f.channels[i].c_str());
  }
  std::printf("gpu      %.1f ms\n", f.gpuMs);
  if (f.reference) std::printf("psnr     %.2f dB (reference %.0f ms)\n", f.psnr, f.referenceMs);
  std::printf("wrote    %s\n", o.out.c_str());
}

void runRenderCommand(const RenderOptions& o) {
  const auto tStart = std::chrono::steady_clock::now();
  createParentFolders(o.out);
  if (!o.referenceOut.empty()) createParentFolders(o.referenceOut);
  if (!o.saveState.empty()) createParentFolders(o.saveState);
  if (o.channelsRequested()) {
    runChannelsCommand(o, o.file.empty() ? defaultVolumeSpec() : o.file);
    return;
  }
  RenderRequest req = requestFrom(o);
  const std::string spec = o.file.empty() ? defaultVolumeSpec() : o.file;
  // The profile first: it sets the host budget the reader must respect.
  Session session(o.profile);
  session.settings() = req.settings;
  RenderTimes times;
  const auto tLoad = std::chrono::steady_clock::now();
  session.open(spec, {.series = o.series,
                      .time = o.time,
                      .channel = o.channel,
                      .region = o.region,
                      .level = o.level,
                      .hostVoxels = needsHostVoxels(o)});
  if (o.labelVolume()) {
    const render::LabelTable table = o.labels.empty()
                                         ? render::LabelTable::defaultFor(session.volume())
                                         : render::LabelTable::load(o.labels);
    req.settings.tf = table.toTransferFunction();
    session.settings().tf = req.settings.tf;
  }
  req.settings.tf = session.settings().tf;  // the modality's default when --tf was not given
  if (!session.defaultNote().empty()) {
    std::fprintf(stderr, "tessera: note: %s\n", session.defaultNote().c_str());
  }
  openFusion(session, o.fusion);
  // --state without --overlay: the state's overlay, as the viewers restore it.
  if (!o.state.empty() && o.fusion.file.empty()) {
    session.restoreOverlay(session::readStateFile(o.state));
  }
  times.loadMs = msSince(tLoad);
  const DeviceSession& device = session.device();
  if (session.streamed()) {
    const RenderResult r = session.run(req);
    r.first.writePng(o.out);
    if (r.referenceImage && !o.referenceOut.empty()) r.referenceImage->writePng(o.referenceOut);
    saveState(o, session);
    times.totalMs = msSince(tStart);
    if (o.json) {
      printRenderJson(o, req, r, device, spec, times, nullptr, httpFetch(*session.pyramid()));
    } else {
      printRenderText(o, req, r, device, session.shape(), spec, times,
                      httpFetch(*session.pyramid()));
    }
    checkRefined(o, r);
    return;
  }
  if (o.lattice != "cartesian") checkSamplesLayout(o, device, session.volume(), req);
  // Checked even when nothing uses it, so that a typo is not silently ignored.
  const render::OverlayOpacity overlayOpacity = render::parseOverlayOpacity(o.overlayOpacity);
  if (!o.overlays.empty() || !o.offscreen.empty() || !o.roi.empty()) {
    if (session.overlay()) {
      throw InputError(
          "--overlay does not combine with --overlays, --offscreen or --roi (the "
          "hybrid compositor draws one volume)");
    }
    runHybridCommand(o, session, req, spec, overlayOpacity);
    saveState(o, session);
    return;
  }
  const RenderResult r = session.run(req);
  r.first.writePng(o.out);
  if (r.referenceImage && !o.referenceOut.empty()) r.referenceImage->writePng(o.referenceOut);
  saveState(o, session);
  times.totalMs = msSince(tStart);
  const nlohmann::json& regionReport = session.regionReport();
  if (o.json) {
    printRenderJson(o, req, r, device, spec, times, regionReport);
  } else {
    printRenderText(o, req, r, device, session.volume(), spec, times);
    if (!regionReport.is_null()) std::printf("region   %s\n", regionReport.dump().c_str());
    if (const session::Overlay* overlay = session.overlay()) printOverlayText(*overlay);
  }
  checkRefined(o, r);
}

}  // namespace

void parseSize(const std::string& text, int& width, int& height) {
  const auto x = text.find('x');
  try {
    if (x == std::string::npos) throw std::invalid_argument("no x");
    std::size_t used = 0;
    width = std::stoi(text.substr(0, x), &used);
    if (used != x) throw std::invalid_argument("junk");
    height = std::stoi(text.substr(x + 1), &used);
    if (used != text.size() - x - 1) throw std::invalid_argument("junk");
  } catch (const std::exception&) {
    throw InputError("--size '" + text + "': expected WIDTHxHEIGHT, e.g. 512x512");
  }
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384) {
    throw InputError("--size '" + text + "': width and height must be 1..16384");
  }
}

void addRenderCommand(CLI::App& app) {
  auto o = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand(
      "render", "Render a volume headless to a PNG (GPU ray caster through EGL)");
  addVolumeOptions(cmd, o->file, o->series);
  addTimeChannelOptions(cmd, o->time, o->channel);
  addDefaultedOption(
      cmd, "--tf", o->tf,
      "Transfer function: preset (grey, mr-default, ct-bone, ct-muscle, bench: over the "
      "volume's window; clinical, each with its own window: ct-bone-hu, ct-soft-tissue, "
      "ct-lung, ct-angio in HU, mr-percentile) or FILE.json; default: the DICOM modality's "
      "(CT ct-soft-tissue, MR mr-percentile), else mr-default. ct-bone is the older bone ramp "
      "on the volume's window; for a CT in HU use ct-bone-hu");
  addSizeOption(cmd, o->size, "Image");
  addDefaultedOption(
      cmd, "--azimuth", o->azimuth,
      "Camera azimuth in degrees about the patient's superior axis (0: looking at the "
      "face from anterior, 90: from the patient's right), for every storage order");
  addDefaultedOption(cmd, "--elevation", o->elevation,
                     "Camera elevation in degrees (90: looking down from superior)");
  addDefaultedOption(cmd, "--zoom", o->zoom, "Zoom factor (>1 magnifies)");
  addDefaultedOption(cmd, "--fov", o->fov, "Vertical field of view in degrees (perspective)");
  cmd->add_flag("--ortho", o->ortho, "Orthographic projection");
  addDefaultedOption(cmd, "--mode", o->mode,
                     renderModeChoices() +
                         ": emission-absorption compositing, or a projection of each ray's "
                         "maximum, minimum or mean sample, shown in the TF colour of that value; "
                         "minip and average by raycast only");
  addSamplingOptions(cmd, o->sampling);
  addDefaultedOption(cmd, "--max-steps", o->maxSteps, "Maximum samples per ray");
  addDefaultedOption(cmd, "--opacity-scale", o->opacityScale, "Global opacity scale");
  addDefaultedOption(cmd, "--ert", o->ert, "Early ray termination threshold (>= 1 disables)");
  cmd->add_flag("--jitter", o->jitter, "Jitter the first sample per pixel");
  addShadingOptions(cmd, o->shading);
  addClippingOptions(cmd, o->clipping);
  o->labelsOption = addLabelsOption(
      cmd, o->labels,
      "Render a label volume (atlas, 8-bit integer labels): nearest-neighbour sampling and a "
      "categorical colour table instead of --tf. TABLE (optional): JSON {\"labels\": "
      "[{\"value\", \"name\", \"color\": [r,g,b] 0..1, \"opacity\", \"visible\"}]} or a label "
      "text file (ITK-SNAP, FreeSurfer LUT, or mricron's IDX NAME); labels it does not name are "
      "hidden. Without TABLE: a default palette for every label present");
  cmd->add_option("--window", o->window,
                  "Value window MIN MAX (raw values); default: the value range")
      ->expected(2);
  cmd->add_option("--background", o->background, "Background colour R G B in [0,1]")->expected(3);
  addDefaultedOption(cmd, "--out", o->out, "Output PNG");
  cmd->add_flag("--reference", o->reference,
                "Also render with the CPU reference and print PSNR/SSIM");
  cmd->add_option("--reference-out", o->referenceOut,
                  "Write the reference image to this PNG (implies --reference)");
  cmd->add_option("--reference-step", o->referenceStep,
                  "Judge quality against a fine reference instead: the CPU reference at this "
                  "step in voxels (e.g. 0.25), every sample, post-classified (implies "
                  "--reference; without it the reference takes the render's own samples)");
  o->referenceLevelOption = cmd->add_option(
      "--reference-level", o->referenceLevel,
      "With a layout that streams a pyramid (bricks: OME-Zarr stores, head:, --layout "
      "bricks): the level the CPU reference reads whole, 0 = the finest (native) level. "
      "Default: per brick cell, the level the refined frame shows there (reference_level: the "
      "finest of them, with a note when it shows several). The level and its double-precision "
      "copy must fit the "
      "host budget: pick a coarser level when they do not (implies --reference)");
  addDefaultedOption(cmd, "--repeat", o->repeat,
                     "Render N frames, rotating the camera, and report timings");
  addDefaultedOption(cmd, "--rotate", o->rotate, "Azimuth step in degrees between repeated frames");
  addDefaultedOption(cmd, "--skip-block", o->skipBlock,
                     "Empty-space skipping block size in voxels (0 = off)");
  addDefaultedOption(cmd, "--lut", o->lut, "Transfer-function table entries (256 or 4096)");
  addDefaultedOption(cmd, "--technique", o->technique,
                     render::TechniqueRegistry::global().describe());
  addDefaultedOption(cmd, "--slices", o->slices,
                     "Slices: slice3d over the volume diagonal (0 = from --step), slice2d drawn "
                     "per stack (0 = every voxel plane)");
  addDefaultedOption(
      cmd, "--classify", o->classify,
      "slice2d classification: pre (CPU RGBA), palette (index + palette) or post (LUT)");
  addDefaultedOption(cmd, "--profile", o->profile,
                     "Device profile to obey (tessera profiles lists them) or FILE.json");
  addDefaultedOption(cmd, "--layout", o->layout,
                     "Volume storage: " + layout::LayoutRegistry::global().choices() +
                         " (auto: the planner chooses)");
  addDefaultedOption(cmd, "--lattice", o->lattice,
                     "Sample lattice: cartesian (the volume's grid, trilinear) or fcc (resampled "
                     "onto the face-centred cubic lattice with a cubic B-spline and "
                     "quasi-interpolation, reconstructed with the six-direction box spline; needs "
                     "an ES 3 profile; --reference then renders the box spline on the CPU)");
  cmd->add_option("--density", o->density,
                  "With --lattice fcc: same (as many lattice points as voxels, default) or half "
                  "(every voxel with an even index sum, no interpolation)");
  cmd->add_flag("--json", o->json, "Print one JSON object instead of text");
  cmd->add_option("--channels", o->channels,
                  "OME-Zarr store: render these channels together, e.g. 0,2 (up to 6; with any "
                  "--channel-* option and no --channels: every channel), with the store's "
                  "omero colours, windows and visibility as defaults (docs/channels.md)");
  cmd->add_option("--channel-colors", o->channelColors,
                  "One RRGGBB colour per channel rendered, e.g. ff0000,00ff00");
  cmd->add_option("--channel-windows", o->channelWindows,
                  "One LO:HI window (raw values) per channel rendered, e.g. 100:2000,50:900");
  cmd->add_option("--channel-mode", o->channelMode,
                  "How channels combine: additive (default; the TF's opacity per channel, "
                  "colours summed) or max (per channel maximum projection)");
  cmd->add_option("--overlays", o->overlays,
                  "Lines drawn at full resolution with the volume: box,axes,roi (any subset); "
                  "with --reference the ground truth stops each ray at its line");
  addDefaultedOption(cmd, "--line-attenuation", o->overlayOpacity,
                     "How the lines of --overlays behind/inside the volume are attenuated: "
                     "alpha (target alpha), two-pass (renders over black and white), luma-avg, "
                     "luma-601");
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
  addDefaultedOption(cmd, "--level", o->level,
                     "With --region: pyramid level, native (0, the finest) or N");
  addFusionOptions(cmd, o->fusion);
  addStateOptions(cmd, o->state, o->saveState,
                  "camera, TF, window, mode, sampling, shading, clipping, technique and layout. "
                  "An option given with it replaces what it sets, the rest stays as saved; the "
                  "volume, --size, --out and the other run options are this command's. A "
                  "viewer's saved exploration is not replayed (render draws the whole volume or "
                  "--region)",
                  "after the render, creating its folder; --state reads it back");
  cmd->footer(
      "Exit status: 0 written; 1 an error (one line on stderr naming the file or URL, nothing "
      "written); 2 an internal error; 3 written but incomplete: a streamed volume's bricks whose "
      "reads kept failing show their coarser level (each failed chunk, file or URL is named on "
      "stderr, \"tessera: incomplete: ...\"), or refining stopped at its limit; 100-127 options "
      "that do not parse.");
  o->command = cmd;
  checkOptionsClassified(*cmd);
  cmd->callback([o] { runRenderCommand(*o); });
}

}  // namespace tessera::app
