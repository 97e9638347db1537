#include "bench/BenchSampling.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli/Commands.h"
#include "cli/SamplingOptions.h"
#include "tessera/core/Error.h"
#include "tessera/core/Timing.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/layout/VolumeUpload.h"
#include "tessera/lod/InCoreVolumeSource.h"
#include "tessera/lod/ProceduralMultiresSource.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/Raycaster.h"
#include "tessera/session/RenderRun.h"

namespace tessera::app {

namespace {

struct Variant {
  Variant(std::string n, RenderSettings s) : name(std::move(n)), settings(std::move(s)) {}
  std::string name;
  RenderSettings settings;
  std::unique_ptr<render::Raycaster> caster;
  std::vector<double> ms;
  double worstPsnr = 999.0;
  double samplesPerRay = 0.0;
  double stepsPerRay = 0.0;
  double tableMs = 0.0;
};

Camera viewCamera(const Volume& volume, int view) {
  return Camera::framing(volume, 60.0 * view, view == 0 ? 0.0 : 20.0);
}

std::string stepName(double step) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", step);
  return buf;
}

RenderSettings variantSettings(const RenderSettings& base, double step, bool pre, bool adaptive,
                               double tolerance, int maxMultiplier) {
  RenderSettings s = base;
  s.stepVoxels = step;
  s.sampling.preintegrate = pre;
  s.sampling.preintegrateLitOnly = false;  // a variant says which it measures
  s.sampling.adaptive = adaptive;
  s.sampling.tolerance = tolerance;
  s.sampling.litTolerance = -1.0;  // lit variants too
  s.sampling.maxMultiplier = maxMultiplier;
  return s;
}

// The ablation at each base step: as before, + pre-integration, + adaptive
// steps, both.
std::vector<Variant> ablation(const SamplingBenchOptions& o, const RenderSettings& base) {
  std::vector<Variant> v;
  for (double step : o.steps) {
    const std::string at = " @" + stepName(step);
    const double tol = o.tolerance;
    const int m = o.maxMultiplier;
    v.emplace_back("baseline" + at, variantSettings(base, step, false, false, tol, m));
    v.emplace_back("+preint" + at, variantSettings(base, step, true, false, tol, m));
    RenderSettings blocksOnly = variantSettings(base, step, false, true, tol, m);
    blocksOnly.sampling.opacityGrowth = false;
    v.emplace_back("+adaptive, blocks only" + at, blocksOnly);
    v.emplace_back("+adaptive" + at, variantSettings(base, step, false, true, tol, m));
    v.emplace_back("+preint +adaptive" + at, variantSettings(base, step, true, true, tol, m));
  }
  return v;
}

// Candidates for the defaults: fixed steps with and without pre-integration,
// and adaptive steps at several tolerances on each base step.
std::vector<Variant> sweep(const SamplingBenchOptions& o, const RenderSettings& base) {
  std::vector<Variant> v;
  const int m = o.maxMultiplier;
  for (double step : o.steps) {
    for (bool pre : {false, true}) {
      const std::string kind = pre ? "pre" : "post";
      v.emplace_back(kind + " @" + stepName(step), variantSettings(base, step, pre, false, 0, m));
      for (double tol : o.tolerances) {
        v.emplace_back(kind + "+adaptive @" + stepName(step) + " tol " + stepName(tol),
                       variantSettings(base, step, pre, true, tol, m));
      }
    }
  }
  return v;
}

struct Config {
  std::string volume;
  std::string tf;
  bool shade = false;
};

nlohmann::json runConfig(const SamplingBenchOptions& o, const Config& config,
                         gpu::GlContext& context, const gpu::DeviceLimits& limits,
                         const lod::InCoreVolumeSource& source) {
  const Volume& volume = source.volume();
  const TransferFunction tf = TransferFunction::fromPresetOrFile(config.tf);
  int width = 0, height = 0;
  parseSize(o.size, width, height);
  const layout::VolumeUpload upload =
      layout::uploadVolume(context, limits, source, {}, "texture3d");

  RenderSettings base;
  base.shading = shadingFrom(o.shadingOptions);
  base.shading.enabled = config.shade;
  std::vector<Variant> variants = o.sweep ? sweep(o, base) : ablation(o, base);

  // The fine references, one per view.
  RenderSettings fine = base;
  fine.stepVoxels = o.referenceStep;
  fine.maxSteps = 65536;
  std::vector<Image> references;
  const auto tRef = std::chrono::steady_clock::now();
  for (int view = 0; view < o.views; ++view) {
    references.push_back(
        renderReference(volume, tf, viewCamera(volume, view), fine, width, height));
  }
  const double referenceMs = msSince(tRef);

  for (Variant& v : variants) {
    v.caster = std::make_unique<render::Raycaster>(context, volume, *upload.layout);
    v.caster->setSkipBlockSize(8);
    v.caster->setPreintegrationEntries(o.preintEntries);
    v.caster->setTransferFunction(tf);
    v.caster->prepare(v.settings);
    v.tableMs =
        usesPreintegration(v.settings) ? v.caster->preintegrationTable().lastBuildMs() : 0.0;
    // Quality: the worst view against the fine reference.
    for (int view = 0; view < o.views; ++view) {
      const Image img = v.caster->render(viewCamera(volume, view), v.settings, width, height);
      v.worstPsnr = std::min(v.worstPsnr, psnr(img, references[static_cast<std::size_t>(view)]));
    }
    // Work: the samples the CPU reference takes walking the same grid, at a
    // lower resolution (samples per ray do not depend on it).
    ReferenceStats stats;
    // The grid the GPU walks: adaptive steps, and the empty blocks it
    // leaves (image-neutral, but they are iterations too).
    const StepGrid* grid = v.caster->stepGrid().valid() ? &v.caster->stepGrid() : nullptr;
    renderReference(volume, tf, viewCamera(volume, 0), v.settings, 128, 128, 0, &stats, nullptr,
                    grid);
    const double rays = static_cast<double>(std::max<std::uint64_t>(1, stats.raysHittingVolume));
    v.samplesPerRay = static_cast<double>(stats.samples) / rays;
    v.stepsPerRay = static_cast<double>(stats.steps) / rays;
  }
  // Speed: frames interleaved variant by variant, so that a shared machine's
  // load falls on all of them alike.
  const Camera camera = viewCamera(volume, 0);
  for (int f = 0; f < o.frames; ++f) {
    Camera cam = camera;
    cam.azimuthDeg += f * o.rotate;
    for (Variant& v : variants) {
      const auto t0 = std::chrono::steady_clock::now();
      v.caster->renderFrame(cam, v.settings, width, height);
      v.ms.push_back(msSince(t0));
    }
    if (!o.json) std::fprintf(stderr, "\rframe %d/%d", f + 1, o.frames);
  }
  if (!o.json) std::fprintf(stderr, "\r%*s\r", 20, "");

  const double base0 = median(variants.front().ms);
  nlohmann::json rows = nlohmann::json::array();
  if (!o.json) {
    std::printf(
        "\n%s, TF %s, %s, %dx%d, %d frames rotating %g deg (interleaved); quality: worst "
        "of %d views vs the %g-voxel reference (every sample, post-classified; %.0f ms "
        "on the CPU)\n\n",
        config.volume.c_str(), config.tf.c_str(), config.shade ? "shaded" : "unshaded", width,
        height, o.frames, o.rotate, o.views, o.referenceStep, referenceMs);
    std::printf(
        "| variant | median ms | speed-up | samples/ray | iterations/ray | PSNR vs fine | table "
        "ms |\n");
    std::printf("|---|---:|---:|---:|---:|---:|---:|\n");
  }
  for (const Variant& v : variants) {
    const double med = median(v.ms);
    if (!o.json) {
      std::printf("| %s | %.1f | %.2f | %.1f | %.1f | %.2f dB | %s |\n", v.name.c_str(), med,
                  base0 / med, v.samplesPerRay, v.stepsPerRay, v.worstPsnr,
                  v.tableMs > 0.0 ? stepName(std::round(v.tableMs * 100.0) / 100.0).c_str() : "—");
    }
    rows.push_back({{"variant", v.name},
                    {"step", v.settings.stepVoxels},
                    {"preintegrate", v.settings.sampling.preintegrate},
                    {"adaptive", v.settings.sampling.adaptive},
                    {"tolerance", v.settings.sampling.tolerance},
                    {"max_multiplier", v.settings.sampling.maxMultiplier},
                    {"opacity_growth", v.settings.sampling.opacityGrowth},
                    {"ms_median", med},
                    {"speedup", base0 / med},
                    {"frame_ms", v.ms},
                    {"samples_per_ray", v.samplesPerRay},
                    {"iterations_per_ray", v.stepsPerRay},
                    {"psnr_vs_fine_db", v.worstPsnr},
                    {"table_build_ms", v.tableMs}});
  }
  return {{"volume", config.volume},
          {"tf", config.tf},
          {"shade", config.shade},
          {"reference_ms", referenceMs},
          {"rows", rows}};
}

// A file, gen:..., or head:N (the generated CT-like head of the bricks
// benchmark, read whole).
Volume readBenchVolume(const std::string& spec) {
  if (lod::ProceduralMultiresSource::isSpec(spec)) {
    const lod::ProceduralMultiresSource head(spec);
    return head.readBox(0, lod::VoxelBox{glm::ivec3(0), head.levelInfo(0).dims});
  }
  return readVolume(spec);
}

}  // namespace

void runSamplingBench(const SamplingBenchOptions& o) {
  if (o.frames < 1) throw InputError("--frames must be >= 1");
  if (!(o.referenceStep > 0.0)) throw InputError("--reference-step must be > 0");
  if (o.views < 1) throw InputError("--views must be >= 1");
  auto context = gpu::GlContext::createHeadless();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(context->caps());
  const std::vector<std::string> volumes =
      o.volumes.empty() ? std::vector<std::string>{defaultVolumeSpec()} : o.volumes;
  if (!o.json) std::printf("GL: %s\n", context->caps().renderer.c_str());
  nlohmann::json configs = nlohmann::json::array();
  for (const std::string& spec : volumes) {
    const lod::InCoreVolumeSource source(readBenchVolume(spec));
    for (const std::string& tf : o.tfs) {
      for (const std::string& shade : o.shading) {
        configs.push_back(runConfig(o, {spec, tf, parseOnOff(shade, "--sampling-shading")},
                                    *context, limits, source));
      }
    }
  }
  if (o.json) {
    nlohmann::json j;
    j["gl_renderer"] = context->caps().renderer;
    j["size"] = o.size;
    j["frames"] = o.frames;
    j["reference_step"] = o.referenceStep;
    j["configs"] = configs;
    std::printf("%s\n", j.dump(2).c_str());
  }
}

}  // namespace tessera::app
