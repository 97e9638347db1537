#include "cli/HybridJob.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/core/Timing.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceOverlay.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/TechniqueRegistry.h"

namespace tessera::app {

namespace {

// Frame 0 against the CPU ground truth: the volume and, in composite mode,
// rays stopped at the overlay lines at full resolution.
void compareWithGroundTruth(const Volume& volume, const TransferFunction& tf,
                            const RenderRequest& req, render::HybridCompositor& compositor,
                            HybridResult& result) {
  const auto tRef = std::chrono::steady_clock::now();
  if (req.settings.render.mode == RenderMode::Composite) {
    result.groundTruth = renderReferenceWithLines(
        volume, tf, req.settings.camera, req.settings.render, req.width, req.height,
        compositor.overlays().readColor(), compositor.overlays().readDistance());
  } else {
    result.groundTruth = renderReference(volume, tf, req.settings.camera, req.settings.render,
                                         req.width, req.height);
  }
  result.groundTruthMs = msSince(tRef);
  result.psnrDb = psnr(result.image, *result.groundTruth);
  result.ssim = ssim(result.image, *result.groundTruth);
}

}  // namespace

HybridResult runHybridRender(DeviceSession& device, const lod::VolumeSource& source,
                             RenderRequest req, const HybridRequest& hybrid) {
  if (req.repeat < 1) throw InputError("--repeat must be >= 1");
  req.settings.validate();
  const TransferFunction& tf = req.settings.tf;
  if (req.settings.render.mode != RenderMode::Composite && hybrid.overlays.any() &&
      hybrid.hybrid.opacity != render::OverlayOpacity::Alpha) {
    throw InputError("--line-attenuation " + render::overlayOpacityName(hybrid.hybrid.opacity) +
                     " needs --mode composite");
  }
  gpu::GlContext& context = *device.context;
  render::TechniqueOnVolume t =
      render::createTechnique(req.settings.technique, context, device.limits, source,
                              req.techniqueOptions(), req.settings.layout);
  const Volume& volume = *t.upload.volume;
  render::Technique& technique = *t.technique;
  technique.setTransferFunction(tf);
  req.settings.camera.frame(volume);
  technique.prepare(req.settings.camera, req.settings.render);
  render::HybridCompositor compositor(context);
  compositor.setOverlayLines(render::overlayLines(volume, hybrid.overlays));

  HybridResult result;
  result.layout = t.storageName();
  result.technique = req.settings.technique;
  for (int i = 0; i < req.repeat; ++i) {
    Camera cam = req.settings.camera;
    cam.azimuthDeg += i * req.rotateDeg;
    const auto t0 = std::chrono::steady_clock::now();
    compositor.render(technique, cam, req.settings.render, volume.extent(), req.width, req.height,
                      hybrid.hybrid);
    result.frameMs.push_back(msSince(t0));
    if (i == 0) {
      result.image = compositor.readImage();
      result.firstTimings = compositor.timings();
      if (req.reference) compareWithGroundTruth(volume, tf, req, compositor, result);
    }
  }
  result.textureBytes = context.ledger().totalBytes();
  return result;
}

void printHybridResult(const HybridResult& r, const RenderRequest& req, const HybridRequest& h,
                       const DeviceSession& device, const std::string& spec, const std::string& out,
                       bool json) {
  const double median = tessera::median(r.frameMs);
  const glm::ivec2 low = h.hybrid.offscreen.resolve(req.width, req.height);
  if (json) {
    nlohmann::json j;
    j["file"] = spec;
    j["out"] = out;
    j["width"] = req.width;
    j["height"] = req.height;
    j["offscreen"] = {low.x, low.y};
    j["volume_target"] = {r.firstTimings.rendered.x, r.firstTimings.rendered.y};
    j["overlays"] = h.overlays.describe();
    j["overlay_opacity"] = render::overlayOpacityName(h.hybrid.opacity);
    j["frames"] = r.frameMs.size();
    j["frame_ms"] = r.frameMs;
    j["ms_median"] = median;
    j["volume_ms"] = r.firstTimings.volumeMs;
    j["overlay_ms"] = r.firstTimings.overlayMs;
    j["composite_ms"] = r.firstTimings.compositeMs;
    j["volume_passes"] = r.firstTimings.volumePasses;
    j["technique"] = r.technique;
    j["layout"] = r.layout;
    j["texture_bytes"] = r.textureBytes;
    j["gl_renderer"] = device.context->caps().renderer;
    if (r.psnrDb) {
      j["psnr_db"] = std::isinf(*r.psnrDb) ? 999.0 : *r.psnrDb;
      j["ssim"] = *r.ssim;
      j["reference_ms"] = r.groundTruthMs;
    } else {
      j["psnr_db"] = nullptr;
      j["ssim"] = nullptr;
    }
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf("wrote %s (%dx%d): hybrid %s, volume at %dx%d, overlays %s, opacity %s\n",
              out.c_str(), req.width, req.height, r.technique.c_str(), r.firstTimings.rendered.x,
              r.firstTimings.rendered.y, h.overlays.describe().c_str(),
              render::overlayOpacityName(h.hybrid.opacity).c_str());
  std::printf("gpu      %s; layout %s; %s on the GPU\n", device.context->caps().renderer.c_str(),
              r.layout.c_str(), formatBytes(r.textureBytes).c_str());
  std::printf(
      "render   %.1f ms (volume %d pass%s %.1f ms, lines %.1f ms, upscale + composite %.1f ms)\n",
      r.frameMs[0], r.firstTimings.volumePasses, r.firstTimings.volumePasses > 1 ? "es" : "",
      r.firstTimings.volumeMs, r.firstTimings.overlayMs, r.firstTimings.compositeMs);
  if (r.frameMs.size() > 1) {
    std::printf("frames   %zu: median %.1f ms, min %.1f, max %.1f\n", r.frameMs.size(), median,
                *std::min_element(r.frameMs.begin(), r.frameMs.end()),
                *std::max_element(r.frameMs.begin(), r.frameMs.end()));
  }
  if (r.psnrDb) {
    std::printf(
        "ground truth %.0f ms on the CPU (full resolution, rays stop at the lines); PSNR %.2f dB, "
        "SSIM %.5f\n",
        r.groundTruthMs, *r.psnrDb, *r.ssim);
  }
}

}  // namespace tessera::app
