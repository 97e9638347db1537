#include "bench/BenchRoofline.h"

#include <chrono>
#include <cstdio>
#include <utility>

#include <nlohmann/json.hpp>

#include "bench/BenchJson.h"
#include "cli/Commands.h"
#include "tessera/core/Error.h"
#include "tessera/core/Timing.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/lod/InCoreVolumeSource.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/Roofline.h"
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/session/RenderRun.h"

namespace tessera::app {

namespace {

struct TechniqueRow {
  std::string technique;
  std::string layoutWish;
  render::TechniqueOnVolume onVolume;
  std::vector<double> ms;
  std::string layout;  // what was built

  double median() const { return tessera::median(ms); }
};

// Samples per frame, counted by the CPU reference on the same rays and step:
// with the settings' early termination (what a ray caster without skipping
// takes) and without it (the whole segment of every ray inside the box).
struct SampleCounts {
  double withErt = 0.0;
  double nominal = 0.0;
};

SampleCounts countSamples(const Volume& volume, const TransferFunction& tf, RenderRequest req) {
  Camera& camera = req.settings.camera;
  camera.frame(volume);
  SampleCounts counts;
  ReferenceStats stats;
  renderReference(volume, tf, camera, req.settings.render, req.width, req.height, 0, &stats);
  counts.withErt = static_cast<double>(stats.samples);
  RenderSettings noErt = req.settings.render;
  noErt.ertThreshold = 2.0;
  stats = {};
  renderReference(volume, tf, camera, noErt, req.width, req.height, 0, &stats);
  counts.nominal = static_cast<double>(stats.samples);
  return counts;
}

double peakOf(const std::vector<render::RooflineRate>& rates, render::RooflineKernel kernel) {
  for (const render::RooflineRate& r : rates)
    if (r.kernel == kernel) return r.fetchesPerSecond;
  return 0.0;
}

void printPeaks(const std::vector<render::RooflineRate>& rates, const render::RooflineOptions& ro) {
  std::printf(
      "peak rates: %dx%d full-screen passes, %d fetches per fragment from a %dx%dx%d R8 "
      "texture (random voxels), rate = pixels x N / (ms - ms of the same pass with no "
      "fetches)\n\n",
      ro.width, ro.height, ro.fetchesPerFragment, ro.volumeDims.x, ro.volumeDims.y,
      ro.volumeDims.z);
  std::printf("| kernel | median ms | ms with 0 fetches | G fetches/s |\n|---|---:|---:|---:|\n");
  for (const render::RooflineRate& r : rates) {
    std::printf("| %s | %.1f | %.1f | %.3f |\n", render::rooflineKernelName(r.kernel), r.msMedian,
                r.msEmptyMedian, r.fetchesPerSecond * 1e-9);
  }
}

}  // namespace

void runRooflineBench(const RooflineBenchOptions& o) {
  const std::string spec = o.file.empty() ? defaultVolumeSpec() : o.file;
  DeviceSession device = openDevice("native");
  const lod::InCoreVolumeSource source(readVolume(spec));
  const Volume& volume = source.volume();
  const TransferFunction tf = TransferFunction::fromPresetOrFile(o.tf);
  RenderRequest base;
  parseSize(o.size, base.width, base.height);
  if (o.frames < 1) throw InputError("--frames must be >= 1");
  base.settings.render = RenderSettings();  // plain sampling: the counted samples
  base.settings.render.stepVoxels = o.step;
  Camera camera;
  camera.frame(volume);

  const render::RooflineOptions ro{.volumeDims = volume.dims(),
                                   .width = base.width,
                                   .height = base.height,
                                   .fetchesPerFragment = o.fetches,
                                   .repeats = o.frames};
  render::RooflineProbe probe(*device.context, ro);

  std::vector<TechniqueRow> rows;
  // Without skipping the ray caster takes exactly the counted samples: its
  // row is the per-sample efficiency; the others include their accelerations.
  struct Setup {
    std::string technique, layout;
    int skipBlock;
    std::string label;
  };
  for (const Setup& setup :
       std::vector<Setup>{{"raycast", "texture3d", 0, "raycast, no skipping"},
                          {"raycast", "texture3d", 8, "raycast, 8^3 skipping"},
                          {"raycast", "mosaic", 8, "raycast, 8^3 skipping"},
                          {"raycast", "packed-mosaic", 8, "raycast, 8^3 skipping"},
                          {"slice3d", "auto", 8, "slice3d"},
                          {"slice2d", "auto", 8, "slice2d"}}) {
    TechniqueRow row{setup.label, setup.layout, {}, {}, {}};
    RenderRequest req = base;
    req.settings.skipBlock = setup.skipBlock;
    row.onVolume = render::createTechnique(setup.technique, *device.context, device.limits, source,
                                           req.techniqueOptions(), setup.layout);
    row.layout = row.onVolume.storageName();
    row.onVolume.technique->setTransferFunction(tf);
    row.onVolume.technique->prepare(camera, base.settings.render);
    rows.push_back(std::move(row));
  }
  // Peak passes and technique frames interleaved, so that a shared machine's
  // load falls on the peaks and the frames alike.
  for (int f = 0; f < o.frames; ++f) {
    probe.measurePass();
    for (TechniqueRow& row : rows) {
      const auto t0 = std::chrono::steady_clock::now();
      row.onVolume.technique->render(camera, base.settings.render, base.width, base.height, 0.0);
      row.ms.push_back(msSince(t0));
    }
    if (!o.json) std::fprintf(stderr, "\rround %d/%d", f + 1, o.frames);
  }
  if (!o.json) std::fprintf(stderr, "\r%-20s\r", "");
  const std::vector<render::RooflineRate> rates = probe.rates();
  const double fetchPeak = peakOf(rates, render::RooflineKernel::Fetch3DIndependent);
  const double samplePeak = peakOf(rates, render::RooflineKernel::Fetch3DThenTf);
  const SampleCounts samples = countSamples(volume, tf, base);

  if (o.json) {
    nlohmann::json j = benchJson(spec, base.width, base.height, device.context->caps().renderer);
    j["step_voxels"] = o.step;
    j["samples_per_frame_ert"] = samples.withErt;
    j["samples_per_frame_nominal"] = samples.nominal;
    for (const render::RooflineRate& r : rates) {
      j["peaks"].push_back({{"kernel", render::rooflineKernelName(r.kernel)},
                            {"ms_median", r.msMedian},
                            {"ms_empty_median", r.msEmptyMedian},
                            {"fetches_per_second", r.fetchesPerSecond}});
    }
    for (const TechniqueRow& row : rows) {
      const double perSecond = samples.withErt / (row.median() * 1e-3);
      j["techniques"].push_back({{"technique", row.technique},
                                 {"layout", row.layout},
                                 {"ms_median", row.median()},
                                 {"frame_ms", row.ms},
                                 {"effective_samples_per_second", perSecond},
                                 {"fraction_of_fetch_peak", perSecond / fetchPeak},
                                 {"fraction_of_sample_peak", perSecond / samplePeak}});
    }
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf("roofline on %s (%s)\n\n", device.context->caps().renderer.c_str(),
              device.context->caps().version.c_str());
  printPeaks(rates, ro);
  std::printf(
      "\ntechniques: %s at %dx%d, front view, %d frames each interleaved with the peak passes, "
      "step %g voxel, TF %s, ERT 0.99; samples/frame counted by the CPU "
      "reference on the same rays: %.3g with ERT (%.3g without). Effective rate = samples with "
      "ERT / median frame time, so skipping shows as a higher rate; the slicers are credited "
      "with the ray caster's samples at the same step.\n\n",
      spec.c_str(), base.width, base.height, o.frames, o.step, tf.name.c_str(), samples.withErt,
      samples.nominal);
  std::printf(
      "| technique | layout | median ms | effective M samples/s | of 3D fetch peak | of fetch + "
      "TF peak |\n|---|---|---:|---:|---:|---:|\n");
  for (const TechniqueRow& row : rows) {
    const double perSecond = samples.withErt / (row.median() * 1e-3);
    std::printf("| %s | %s | %.1f | %.1f | %.1f %% | %.1f %% |\n", row.technique.c_str(),
                row.layout.c_str(), row.median(), perSecond * 1e-6, 100.0 * perSecond / fetchPeak,
                100.0 * perSecond / samplePeak);
  }
}

}  // namespace tessera::app
