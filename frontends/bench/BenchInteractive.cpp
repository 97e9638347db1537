#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "bench/BenchHybrid.h"
#include "bench/BenchJson.h"
#include "cli/Commands.h"
#include "tessera/core/Error.h"
#include "tessera/core/Timing.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/lod/InCoreVolumeSource.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceOverlay.h"
#include "tessera/render/HybridCompositor.h"
#include "tessera/render/QualityController.h"
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/session/RenderRun.h"

namespace tessera::app {

// A simulated interaction: the camera turns by --rotate per frame for
// --frames frames while the quality controller picks the offscreen size and
// sample distance for the goal, then the user lets go and one idle frame at
// full quality follows.
void runInteractiveBench(const HybridBenchOptions& o) {
  if (o.frames < 1) throw InputError("--frames must be >= 1");
  const std::string spec = o.file.empty() ? defaultVolumeSpec() : o.file;
  const lod::InCoreVolumeSource source(readVolume(spec));
  const TransferFunction tf = TransferFunction::fromPresetOrFile(o.tf);
  int width = 0, height = 0;
  parseSize(o.size, width, height);
  auto context = gpu::GlContext::createHeadless();
  const render::TechniqueOnVolume t =
      render::createTechnique("raycast", *context, gpu::DeviceLimits::of(context->caps()), source,
                              {.imageSize = {width, height}}, "texture3d");
  const Volume& volume = *t.upload.volume;
  render::Technique& technique = *t.technique;
  RenderSettings full;
  full.stepVoxels = o.step;
  Camera camera;
  camera.frame(volume);
  technique.setTransferFunction(tf);
  technique.prepare(camera, full);
  render::HybridCompositor compositor(*context);
  compositor.setOverlayLines(
      render::overlayLines(volume, render::OverlayOptions::parse("box,axes")));

  auto renderAt = [&](const Camera& cam, const render::QualityLevel& q) {
    RenderSettings s = full;
    s.stepVoxels = o.step * q.stepScale;
    technique.prepare(cam, s);  // a new step rebuilds the TF table outside the timed frame
    const auto t0 = std::chrono::steady_clock::now();
    compositor.render(technique, cam, s, volume.extent(), width, height,
                      {render::OffscreenSize::ofFactor(std::min(1.0, q.resolutionScale)),
                       render::OverlayOpacity::Alpha});
    return msSince(t0);
  };

  // One full-quality frame first (warm-up, and the scale of the goal).
  renderAt(camera, render::QualityLevel{});
  const double fullMs = renderAt(camera, render::QualityLevel{});
  render::QualityController::Options qo;
  qo.goalMs = o.goalMs > 0.0 ? o.goalMs : std::round(fullMs / 6.0);
  render::QualityController qc(qo);
  qc.report(render::QualityLevel{}, fullMs);

  struct Row {
    int frame;
    std::string state;
    glm::ivec2 target;
    double step;
    double ms;
  };
  std::vector<Row> rows;
  qc.setInteracting(true);
  Camera cam = camera;
  for (int f = 1; f <= o.frames; ++f) {
    cam.azimuthDeg += o.rotate;
    const render::QualityLevel q = qc.next();
    const double ms = renderAt(cam, q);
    qc.report(q, ms);
    rows.push_back({f, "interacting", compositor.timings().offscreen, o.step * q.stepScale, ms});
    if (!o.json) std::fprintf(stderr, "\rframe %d/%d", f, o.frames);
  }
  const Image lastMoving = compositor.readImage();
  qc.setInteracting(false);
  Image idle;
  while (qc.needsFrame()) {
    const render::QualityLevel q = qc.next();
    const double ms = renderAt(cam, q);
    qc.report(q, ms);
    rows.push_back(
        {o.frames + 1, "idle", compositor.timings().offscreen, o.step * q.stepScale, ms});
    idle = compositor.readImage();
  }
  if (!o.json) std::fprintf(stderr, "\r%*s\r", 20, "");
  // The idle frame against the ground truth, and what the last moving frame
  // gave up against it.
  const Image truth = renderReferenceWithLines(volume, tf, cam, full, width, height,
                                               compositor.overlays().readColor(),
                                               compositor.overlays().readDistance());
  const double idlePsnr = psnr(idle, truth);
  const double movingPsnr = psnr(lastMoving, idle);

  // Settling: frames after the first three.
  std::vector<double> settled;
  int within = 0;
  for (const Row& r : rows) {
    if (r.state != "interacting" || r.frame <= 3) continue;
    settled.push_back(r.ms);
    within += std::abs(r.ms - qo.goalMs) <= 0.25 * qo.goalMs;
  }
  const double settledMedian = median(settled);

  if (o.json) {
    nlohmann::json j = benchJson(spec, width, height, context->caps().renderer);
    j["goal_ms"] = qo.goalMs;
    j["full_quality_ms"] = fullMs;
    nlohmann::json jr = nlohmann::json::array();
    for (const Row& r : rows) {
      jr.push_back({{"frame", r.frame},
                    {"state", r.state},
                    {"target", {r.target.x, r.target.y}},
                    {"step_voxels", r.step},
                    {"ms", r.ms}});
    }
    j["frames"] = jr;
    j["settled_median_ms"] = settledMedian;
    j["settled_within_25_percent"] = within;
    j["settled_frames"] = settled.size();
    j["idle_psnr_vs_ground_truth"] = idlePsnr;
    j["last_moving_psnr_vs_idle"] = movingPsnr;
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf(
      "interactive: %s at %dx%d, TF %s, overlays box+axes; full quality (volume %dx%d, step %g) "
      "takes %.1f ms; goal while moving %.0f ms; %d moving frames rotating %g deg, then idle\n\n",
      spec.c_str(), width, height, tf.name.c_str(), width, height, o.step, fullMs, qo.goalMs,
      o.frames, o.rotate);
  std::printf("| frame | state | volume target | step (voxels) | ms | goal ms |\n");
  std::printf("|---:|---|---|---:|---:|---:|\n");
  for (const Row& r : rows) {
    std::printf("| %d | %s | %dx%d | %.2f | %.1f | %s |\n", r.frame, r.state.c_str(), r.target.x,
                r.target.y, r.step, r.ms,
                r.state == "idle" ? "— (full quality)"
                                  : std::to_string(static_cast<int>(qo.goalMs)).c_str());
  }
  std::printf(
      "\nmoving frames 4..%d: median %.1f ms for a %.0f ms goal, %d of %zu within 25 %%\n"
      "idle frame: full quality, PSNR %.2f dB vs the CPU ground truth; the last moving frame "
      "scores %.2f dB vs it\n",
      o.frames, settledMedian, qo.goalMs, within, settled.size(), idlePsnr, movingPsnr);
}

}  // namespace tessera::app
