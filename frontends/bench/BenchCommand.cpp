#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "bench/BenchBrickWalk.h"
#include "bench/BenchBricks.h"
#include "bench/BenchExplore.h"
#include "bench/BenchFcc.h"
#include "bench/BenchHybrid.h"
#include "bench/BenchJson.h"
#include "bench/BenchPeers.h"
#include "bench/BenchPlayback.h"
#include "bench/BenchRoofline.h"
#include "bench/BenchSampling.h"
#include "bench/BenchScale.h"
#include "bench/BenchSlicing.h"
#include "cli/Commands.h"
#include "cli/ShadingOptions.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/core/Timing.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/layout/MosaicLayout.h"
#include "tessera/layout/PackedMosaicLayout.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/layout/VolumeUpload.h"
#include "tessera/lod/InCoreVolumeSource.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/session/RenderRun.h"

namespace tessera::app {

namespace {

struct BenchOptions {
  std::string file;
  std::string size = "512x512";
  int frames = 36;
  double rotate = 10.0;
  double step = 0.5;
  std::string tf = "bench";
  bool json = false;
  bool layouts = false;
  bool fcc = false;
  std::string fccOut;
  bool slicing = false;
  std::string slicingOut;
  bool slicingQuick = false;
  bool hybrid = false;
  bool interactive = false;
  std::string hybridOut;
  double goalMs = 0.0;
  std::vector<std::string> bricks;  // --bricks: generated volumes to stream
  std::vector<std::string> bricksProfiles{"shield-k1", "ipad2"};
  std::vector<std::string> bricksVsInCore;  // --bricks-vs-incore
  bool scale = false;                       // --scale (BenchScale.h)
  ScaleBenchOptions scaleOptions;
  bool bricksVsInCoreSet = false;
  int rounds = 3;
  bool printTf = false;
  bool roofline = false;
  int fetches = 128;
  ShadingOptions shading;
  // --sampling / --sampling-sweep (BenchSampling.h).
  bool sampling = false;
  bool samplingSweep = false;
  std::vector<std::string> samplingVolumes;
  std::vector<std::string> samplingTfs;
  std::vector<double> samplingSteps{0.5, 1.0};
  std::vector<std::string> samplingShading;
  double samplingTolerance = 0.1;
  std::vector<double> samplingTolerances{0.25, 0.5, 1.0};
  int samplingMax = 16;
  int preintEntries = 256;
  double referenceStep = 0.25;
  int views = 2;
};

struct Variant {
  const char* name;
  int skipBlock;
  double ert;
  std::unique_ptr<render::Technique> caster;
  RenderSettings settings;
  std::vector<double> ms;
  double psnrDb = 0.0;
  double ssim = 0.0;
  double samplesPerRay = 0.0;
};

// The ray caster from the registry on a volume and layout uploaded already.
std::unique_ptr<render::Technique> raycaster(gpu::GlContext& context,
                                             const gpu::DeviceLimits& limits, const Volume& volume,
                                             const layout::Layout& layout, int skipBlock = 8) {
  const render::TechniqueOptions options{.skipBlock = skipBlock};
  return render::TechniqueRegistry::global().create("raycast", {.context = context,
                                                                .limits = limits,
                                                                .volume = volume,
                                                                .layout = &layout,
                                                                .options = options});
}

// The ray-casting benchmark of the Foundation issue: ch2 at 512x512, 36
// frames rotating 10 degrees, 0.5-voxel steps, TF "bench", with the
// accelerations switched on one at a time to show where the time goes.
// Variants are interleaved frame by frame, so that the load of a shared
// machine falls on all of them alike and their ratios stay meaningful.
void runBench(const BenchOptions& o) {
  const std::string spec = o.file.empty() ? defaultVolumeSpec() : o.file;
  const lod::InCoreVolumeSource source(readVolume(spec));
  const Volume& volume = source.volume();
  const TransferFunction tf = TransferFunction::fromPresetOrFile(o.tf);
  auto context = gpu::GlContext::createHeadless();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(context->caps());
  int width = 0, height = 0;
  parseSize(o.size, width, height);
  if (o.frames < 1) throw InputError("--frames must be >= 1");
  const layout::VolumeUpload upload =
      layout::uploadVolume(*context, limits, source, {}, "texture3d");

  std::vector<Variant> variants;
  variants.push_back({"plain (no ERT, no skipping)", 0, 2.0, nullptr, {}, {}, 0, 0, 0});
  variants.push_back({"early ray termination 0.99", 0, 0.99, nullptr, {}, {}, 0, 0, 0});
  variants.push_back({"ERT + empty-space skipping 4^3", 4, 0.99, nullptr, {}, {}, 0, 0, 0});
  variants.push_back({"ERT + empty-space skipping 8^3", 8, 0.99, nullptr, {}, {}, 0, 0, 0});
  variants.push_back({"ERT + empty-space skipping 16^3", 16, 0.99, nullptr, {}, {}, 0, 0, 0});
  const Shading shading = shadingFrom(o.shading);
  if (shading.enabled) {
    // What shading costs, in the same run: the default accelerations unshaded.
    variants.push_back({"ERT + skipping 8^3, unshaded", 8, 0.99, nullptr, {}, {}, 0, 0, 0});
  }
  Camera camera;
  camera.frame(volume);
  for (Variant& v : variants) {
    v.settings.stepVoxels = o.step;
    v.settings.ertThreshold = v.ert;
    v.settings.shading = shading;
    if (std::string(v.name).ends_with("unshaded")) v.settings.shading.enabled = false;
    v.caster = raycaster(*context, limits, volume, *upload.layout, v.skipBlock);
    v.caster->setTransferFunction(tf);
    v.caster->prepare(camera, v.settings);
  }
  for (int f = 0; f < o.frames; ++f) {
    Camera cam = camera;
    cam.azimuthDeg += f * o.rotate;
    for (Variant& v : variants) {
      const auto t0 = std::chrono::steady_clock::now();
      v.caster->render(cam, v.settings, width, height, 0.0);
      v.ms.push_back(msSince(t0));
      if (f == 0) {
        // Each variant is compared with the reference of its own semantics
        // (without ERT the reference also runs to the end of the ray).
        const Image img = v.caster->readImage();
        ReferenceStats stats;
        const Image ref = renderReference(volume, tf, cam, v.settings, width, height, 0, &stats);
        v.psnrDb = psnr(img, ref);
        v.ssim = ssim(img, ref);
        v.samplesPerRay = stats.raysHittingVolume ? static_cast<double>(stats.samples) /
                                                        static_cast<double>(stats.raysHittingVolume)
                                                  : 0.0;
      }
    }
    if (!o.json) std::fprintf(stderr, "\rframe %d/%d", f + 1, o.frames);
  }
  if (!o.json) std::fprintf(stderr, "\r%*s\r", 20, "");

  if (o.json) {
    nlohmann::json rows = nlohmann::json::array();
    for (const Variant& v : variants) {
      rows.push_back({{"variant", v.name},
                      {"skip_block", v.skipBlock},
                      {"ert", v.ert},
                      {"ms_median", median(v.ms)},
                      {"ms_min", *std::min_element(v.ms.begin(), v.ms.end())},
                      {"ms_max", *std::max_element(v.ms.begin(), v.ms.end())},
                      {"frame_ms", v.ms},
                      {"psnr_db", v.psnrDb},
                      {"ssim", v.ssim},
                      {"samples_per_ray", v.samplesPerRay},
                      {"shade", v.settings.shading.enabled},
                      {"occupied_block_fraction", v.caster->report().occupiedBlockFraction}});
    }
    nlohmann::json j = benchJson(spec, width, height, context->caps().renderer);
    j["frames"] = o.frames;
    j["rows"] = rows;
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf("ray casting %s at %dx%d, %d frames rotating %g deg, step %g voxel, TF %s%s\n",
              spec.c_str(), width, height, o.frames, o.rotate, o.step, o.tf.c_str(),
              shading.enabled ? ", shaded (but the unshaded row)" : "");
  std::printf("GL: %s; variants interleaved frame by frame\n\n", context->caps().renderer.c_str());
  std::printf(
      "| variant | median ms | min ms | max ms | occupied blocks | samples/ray (ref, frame 0) | "
      "PSNR dB (frame 0) | SSIM |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const Variant& v : variants) {
    std::printf(
        "| %s | %.1f | %.1f | %.1f | %s | %.0f | %.2f | %.5f |\n", v.name, median(v.ms),
        *std::min_element(v.ms.begin(), v.ms.end()), *std::max_element(v.ms.begin(), v.ms.end()),
        v.skipBlock ? (std::to_string(
                           static_cast<int>(100 * v.caster->report().occupiedBlockFraction + 0.5)) +
                       " %")
                          .c_str()
                    : "—",
        v.samplesPerRay, v.psnrDb, v.ssim);
  }
}

struct LayoutVariant {
  std::string name;
  std::unique_ptr<layout::Layout> layout;
  std::unique_ptr<render::Technique> caster;
  std::vector<double> ms;
  Image first;
};

// The cost of the texture coordinate adapter (Noguera & Jiménez 2012): the
// same ray caster and settings on each layout, frames interleaved so that a
// shared machine's load falls on all alike; ratios to texture3d.
void runLayoutBench(const BenchOptions& o) {
  const std::string spec = o.file.empty() ? defaultVolumeSpec() : o.file;
  const Volume volume = readVolume(spec);
  const TransferFunction tf = TransferFunction::fromPresetOrFile(o.tf);
  auto context = gpu::GlContext::createHeadless();
  int width = 0, height = 0;
  parseSize(o.size, width, height);
  if (o.frames < 1) throw InputError("--frames must be >= 1");
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(context->caps());
  gpu::DeviceLimits small = limits;
  small.max2DTextureSize = 1024;  // forces packed-mosaic across several textures

  std::vector<LayoutVariant> variants;
  variants.push_back({"texture3d",
                      layout::Texture3DLayout::create(volume, limits, context->ledger()),
                      {},
                      {},
                      {}});
  variants.push_back(
      {"mosaic", layout::MosaicLayout::create(volume, limits, context->ledger()), {}, {}, {}});
  variants.push_back({"packed-mosaic",
                      layout::PackedMosaicLayout::create(volume, limits, context->ledger(), 14),
                      {},
                      {},
                      {}});
  variants.push_back({"packed-mosaic, 1024² textures",
                      layout::PackedMosaicLayout::create(volume, small, context->ledger(), 14),
                      {},
                      {},
                      {}});
  RenderSettings settings;
  settings.stepVoxels = o.step;
  settings.shading = shadingFrom(o.shading);
  Camera camera;
  camera.frame(volume);
  for (LayoutVariant& v : variants) {
    v.caster = raycaster(*context, limits, volume, *v.layout);
    v.caster->setTransferFunction(tf);
    v.caster->prepare(camera, settings);
  }
  for (int f = 0; f < o.frames; ++f) {
    Camera cam = camera;
    cam.azimuthDeg += f * o.rotate;
    for (LayoutVariant& v : variants) {
      const auto t0 = std::chrono::steady_clock::now();
      v.caster->render(cam, settings, width, height, 0.0);
      v.ms.push_back(msSince(t0));
      if (f == 0) v.first = v.caster->readImage();
    }
    if (!o.json) std::fprintf(stderr, "\rframe %d/%d", f + 1, o.frames);
  }
  if (!o.json) std::fprintf(stderr, "\r%*s\r", 20, "");
  const Image ref = renderReference(volume, tf, camera, settings, width, height);
  const double base = median(variants[0].ms);
  nlohmann::json rows = nlohmann::json::array();
  if (!o.json) {
    std::printf(
        "layouts: ray casting %s at %dx%d, %d frames rotating %g deg, step %g voxel, TF %s, "
        "ERT + 8^3 skipping\nGL: %s; variants interleaved frame by frame\n\n",
        spec.c_str(), width, height, o.frames, o.rotate, o.step, o.tf.c_str(),
        context->caps().renderer.c_str());
    std::printf(
        "| layout | textures | median ms | min ms | ÷ texture3d | PSNR vs reference | PSNR vs "
        "texture3d |\n");
    std::printf("|---|---|---:|---:|---:|---:|---:|\n");
  }
  for (const LayoutVariant& v : variants) {
    const double med = median(v.ms);
    const double vsRef = psnr(v.first, ref);
    const double vs3d = psnr(v.first, variants[0].first);
    std::string textures;
    for (const auto& t : v.layout->plan().textures) {
      if (!textures.empty()) textures += " + ";
      textures += (t.is3D ? std::to_string(t.size.x) + "x" + std::to_string(t.size.y) + "x" +
                                std::to_string(t.size.z)
                          : std::to_string(t.size.x) + "x" + std::to_string(t.size.y)) +
                  " " + t.format;
    }
    if (!o.json) {
      std::printf(
          "| %s | %s | %.1f | %.1f | %.2f | %.2f dB | %s |\n", v.name.c_str(), textures.c_str(),
          med, *std::min_element(v.ms.begin(), v.ms.end()), med / base, vsRef,
          std::isinf(vs3d) ? "identical" : (std::to_string(vs3d).substr(0, 5) + " dB").c_str());
    }
    rows.push_back({{"layout", v.name},
                    {"textures", textures},
                    {"ms_median", med},
                    {"ratio_to_texture3d", med / base},
                    {"psnr_vs_reference", vsRef},
                    {"psnr_vs_texture3d", std::isinf(vs3d) ? 999.0 : vs3d},
                    {"frame_ms", v.ms}});
  }
  if (o.json) {
    nlohmann::json j = benchJson(spec, width, height, context->caps().renderer);
    j["frames"] = o.frames;
    j["rows"] = rows;
    std::printf("%s\n", j.dump(2).c_str());
  }
}

}  // namespace

// The suites and switches of `tessera bench`, each a flag.
struct BenchFlag {
  const char* name;
  bool BenchOptions::*member;
  const char* help;
};
constexpr BenchFlag kBenchFlags[] = {
    {"--layouts", &BenchOptions::layouts,
     "Compare layouts (texture3d, mosaic, packed-mosaic) instead of accelerations"},
    {"--fcc", &BenchOptions::fcc,
     "FCC lattice + box spline vs Cartesian + trilinear (Sarfaraz & Shaban 2015 "
     "Tables 1-2): 64^3-class volumes, FCC at the same and half the sample count, "
     "and where the box spline's time goes; --frames per variant (default 12)"},
    {"--json", &BenchOptions::json, "Print JSON instead of a Markdown table"},
    {"--slicing", &BenchOptions::slicing,
     "Texture slicing vs ray casting (GRAPP 2012 Tables 1-2), TF-update times "
     "(Moser & Weiskopf 2008 Fig. 6) and quality per count; --frames per cell"},
    {"--slicing-quick", &BenchOptions::slicingQuick, "With --slicing: a small smoke run"},
    {"--hybrid", &BenchOptions::hybrid,
     "Hybrid low/high-resolution rendering: each line-attenuation method vs the ground "
     "truth (Moser & Weiskopf 2008 Fig. 2) and full vs 128x128/256x256/256x512 "
     "offscreen speed at 480x640 and 1024x768; --frames per cell"},
    {"--interactive", &BenchOptions::interactive,
     "Quality controller: --frames moving frames held near a frame-time goal, then one "
     "full-quality idle frame (default size 480x640)"},
    {"--print-tf", &BenchOptions::printTf,
     "Print --tf as JSON (control points, opacity unit length) and exit: what "
     "bench/peers translates into VTK's transfer functions"},
    {"--roofline", &BenchOptions::roofline,
     "Platform roofline: peak trilinear 3D fetch and TF lookup rates of this context, "
     "and each technique's effective samples/s as a fraction of them (default 5 "
     "frames per technique)"},
    {"--sampling", &BenchOptions::sampling,
     "Fewer samples for the same image: baseline / +pre-integration / +adaptive / "
     "both at each --sampling-steps, interleaved; ms, samples per ray, PSNR vs the "
     "--reference-step reference (default 8 frames)"},
    {"--sampling-sweep", &BenchOptions::samplingSweep,
     "Candidate sampling settings (fixed steps, pre-integration, adaptive "
     "tolerances) per volume x TF x shading: how tessera render's defaults were "
     "chosen (docs/sampling.md)"},
};

// The suites that write files, each with its folder option.
struct BenchFolder {
  const char* name;
  std::string BenchOptions::*member;
  const char* help;
};
constexpr BenchFolder kBenchFolders[] = {
    {"--fcc-out", &BenchOptions::fccOut,
     "FCC quality figures instead of speed: Marschner-Lobb RMS/PSNR at 41^3 and "
     "64^3 (Cartesian trilinear vs FCC box spline, same and half density), ch2 on "
     "FCC vs the original; tables on stdout, PNGs in this folder"},
    {"--slicing-out", &BenchOptions::slicingOut,
     "With --slicing: also write bench-slicing.md and SVG plots to this folder"},
    {"--hybrid-out", &BenchOptions::hybridOut,
     "With --hybrid: write the pictures (ground truth, each method) to this folder"},
};

void addBenchCommand(CLI::App& app) {
  auto o = std::make_shared<BenchOptions>();
  CLI::App* cmd = app.add_subcommand("bench",
                                     "Ray-casting benchmark: N rotating frames per acceleration "
                                     "variant (interleaved), with PSNR vs "
                                     "the CPU reference");
  cmd->add_option("file", o->file, "Volume (default: ch2 or a phantom)");
  addSizeOption(cmd, o->size, "Image");
  addDefaultedOption(cmd, "--frames", o->frames, "Frames per variant");
  addDefaultedOption(cmd, "--rotate", o->rotate, "Azimuth step per frame in degrees");
  addDefaultedOption(cmd, "--step", o->step, "Sample distance in voxels");
  addDefaultedOption(cmd, "--tf", o->tf, "Transfer function preset or JSON file");
  addShadingOptions(cmd, o->shading);
  for (const BenchFlag& f : kBenchFlags) cmd->add_flag(f.name, (*o).*f.member, f.help);
  for (const BenchFolder& f : kBenchFolders) cmd->add_option(f.name, (*o).*f.member, f.help);
  cmd->add_option(
      "--bricks", o->bricks,
      "Large volumes through the bricks layout: generated head:WxHxD specs (head16: in u16; e.g. "
      "head:512x512x894 head:1024); per profile the first and refined image, rotating "
      "frame time while streaming (default 8 frames), levels, texture bytes vs the "
      "budget, bricks read, peak RSS, and the in-core layout as baseline where it fits");
  addDefaultedOption(cmd, "--bricks-profiles", o->bricksProfiles, "Profiles for --bricks");
  cmd->add_flag("--scale", o->scale,
                "The generated u16 head (head16:N) from 512^3 to 8192^3 through bricks per "
                "profile: first and refined image, bricks generated, texture peak vs budget, "
                "host RSS peak vs budget, one process per row (docs/large-data.md)");
  addDefaultedOption(cmd, "--scale-sides", o->scaleOptions.sides, "With --scale: volume sides N");
  addDefaultedOption(cmd, "--scale-profiles", o->scaleOptions.profiles, "With --scale: profiles");
  cmd->add_option_function<std::vector<std::string>>(
         "--bricks-vs-incore",
         [o](const std::vector<std::string>& v) {
           for (const std::string& s : v) {
             if (!s.empty()) o->bricksVsInCore.push_back(s);
           }
           o->bricksVsInCoreSet = true;
         },
         "What the bricks layout costs against in-core for volumes that fit both: alternating "
         "runs of the same view at full resolution, frame time ratio and PSNR between the "
         "images. Files or gen: specs, u16:SPEC widens SPEC to 16 bits (default: ch2, "
         "gen:shepp-logan:384, u16:gen:shepp-logan:512)")
      ->expected(0, -1);
  addDefaultedOption(cmd, "--rounds", o->rounds, "With --bricks-vs-incore: alternating rounds");
  cmd->add_option("--goal-ms", o->goalMs,
                  "With --interactive: frame-time goal (default: a sixth of a full-quality frame)");
  addDefaultedOption(cmd, "--fetches", o->fetches,
                     "With --roofline: fetches per fragment in the peak "
                     "passes");
  cmd->add_option("--sampling-volumes", o->samplingVolumes,
                  "With --sampling(-sweep): volumes (default: FILE or ch2)");
  cmd->add_option("--sampling-tfs", o->samplingTfs,
                  "With --sampling(-sweep): transfer functions (default: --tf)");
  addDefaultedOption(cmd, "--sampling-steps", o->samplingSteps,
                     "With --sampling(-sweep): base steps");
  cmd->add_option("--sampling-shading", o->samplingShading,
                  "With --sampling(-sweep): off, on or both (default: --shade)");
  addDefaultedOption(cmd, "--adaptive-tolerance", o->samplingTolerance,
                     "With --sampling: the adaptive variants' tolerance");
  addDefaultedOption(cmd, "--sampling-tolerances", o->samplingTolerances,
                     "With --sampling-sweep: the adaptive tolerances tried");
  addDefaultedOption(cmd, "--adaptive-max", o->samplingMax,
                     "With --sampling(-sweep): the largest step multiple");
  addDefaultedOption(cmd, "--preint-size", o->preintEntries,
                     "With --sampling(-sweep): pre-integration table entries per axis");
  addDefaultedOption(cmd, "--reference-step", o->referenceStep,
                     "With --sampling(-sweep): the fine reference's step in voxels");
  addDefaultedOption(cmd, "--views", o->views,
                     "With --sampling(-sweep): views whose worst PSNR counts");
  addExploreBenchOptions(cmd);
  addPeersBenchOptions(cmd);
  addPlaybackBenchOptions(cmd);
  cmd->callback([o] {
    if (runExploreBenchIfAsked()) return;
    if (runPlaybackBenchIfAsked()) return;
    if (runPeersBenchIfAsked()) return;
    if (o->sampling || o->samplingSweep) {
      SamplingBenchOptions s;
      s.volumes = o->samplingVolumes;
      if (s.volumes.empty() && !o->file.empty()) s.volumes.push_back(o->file);
      s.tfs = o->samplingTfs.empty() ? std::vector<std::string>{o->tf} : o->samplingTfs;
      s.steps = o->samplingSteps;
      s.size = o->size;
      s.frames = o->frames == 36 ? 8 : o->frames;
      s.rotate = o->rotate;
      s.referenceStep = o->referenceStep;
      s.views = o->views;
      s.shadingOptions = o->shading;
      s.shading = o->samplingShading.empty()
                      ? std::vector<std::string>{o->shading.shade ? "on" : "off"}
                      : o->samplingShading;
      if (s.shading.size() == 1 && s.shading[0] == "both") s.shading = {"off", "on"};
      s.tolerance = o->samplingTolerance;
      s.tolerances = o->samplingTolerances;
      s.maxMultiplier = o->samplingMax;
      s.preintEntries = o->preintEntries;
      s.sweep = o->samplingSweep;
      s.json = o->json;
      runSamplingBench(s);
      return;
    }
    if (o->roofline) {
      runRooflineBench({.file = o->file,
                        .size = o->size,
                        .frames = o->frames == 36 ? 5 : o->frames,
                        .step = o->step,
                        .tf = o->tf,
                        .fetches = o->fetches,
                        .json = o->json});
      return;
    }
    if (o->printTf) {
      std::printf("%s\n", TransferFunction::fromPresetOrFile(o->tf).toJson().c_str());
      return;
    }
    if (o->hybrid || o->interactive) {
      const HybridBenchOptions h{.file = o->file,
                                 .frames = o->frames == 36 ? (o->hybrid ? 5 : 20) : o->frames,
                                 .rotate = o->rotate == 10.0 ? 5.0 : o->rotate,
                                 .step = o->step,
                                 .tf = o->tf,
                                 .outDir = o->hybridOut,
                                 .goalMs = o->goalMs,
                                 .size = o->size == "512x512" ? "480x640" : o->size,
                                 .json = o->json};
      o->hybrid ? runHybridBench(h) : runInteractiveBench(h);
      return;
    }
    if (!o->fccOut.empty()) {
      int width = 0, height = 0;
      parseSize(o->size == "512x512" ? "256x256" : o->size, width, height);
      runFccQuality(o->fccOut, width);
      return;
    }
    if (o->fcc) {
      runFccBench({.size = o->size,
                   .frames = o->frames == 36 ? 12 : o->frames,
                   .rotate = o->rotate,
                   .step = o->step,
                   .tf = o->tf,
                   .json = o->json});
      return;
    }
    if (o->slicing) {
      runSlicingBench({.file = o->file,
                       .frames = o->frames == 36 ? 3 : o->frames,
                       .tf = o->tf,
                       .outDir = o->slicingOut,
                       .quick = o->slicingQuick});
      return;
    }
    if (o->bricksVsInCoreSet) {
      BrickWalkBenchOptions b;
      b.volumes = o->bricksVsInCore;
      if (b.volumes.empty()) {
        b.volumes = {defaultVolumeSpec(), "gen:shepp-logan:384", "u16:gen:shepp-logan:512"};
      }
      b.size = o->size;
      b.frames = o->frames == 36 ? 6 : o->frames;
      b.rounds = o->rounds;
      b.tf = o->tf == "bench" ? "mr-default" : o->tf;
      runBrickWalkBench(b);
      return;
    }
    if (o->scale) {
      o->scaleOptions.size = o->size;
      if (o->tf != "bench") o->scaleOptions.tf = o->tf;
      runScaleBench(o->scaleOptions);
      return;
    }
    if (!o->bricks.empty()) {
      BricksBenchOptions b;
      b.volumes = o->bricks;
      b.profiles = o->bricksProfiles;
      b.size = o->size;
      b.frames = o->frames == 36 ? 8 : o->frames;
      b.rotate = o->rotate;
      b.tf = o->tf == "bench" ? "ct-bone" : o->tf;
      runBricksBench(b);
      return;
    }
    o->layouts ? runLayoutBench(*o) : runBench(*o);
  });
}

}  // namespace tessera::app
