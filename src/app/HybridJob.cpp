#include "app/HybridJob.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/lod/Downsample.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceOverlay.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/HybridRaycastTechnique.h"
#include "tessera/render/HybridSliceTechnique.h"
#include "tessera/render/Raycaster.h"
#include "tessera/render/Slice2DRenderer.h"
#include "tessera/render/Slice3DRenderer.h"

namespace tessera::app {

namespace {
double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

HybridResult runHybridRender(DeviceSession& device, const Volume& fullVolume,
                             const TransferFunction& tf, RenderRequest req,
                             const HybridRequest& hybrid) {
  if (req.repeat < 1) throw InputError("--repeat must be >= 1");
  if (req.settings.mode != RenderMode::Composite && hybrid.overlays.any() &&
      hybrid.hybrid.opacity != render::OverlayOpacity::Alpha) {
    throw InputError("--overlay-opacity " + render::overlayOpacityName(hybrid.hybrid.opacity) +
                     " needs --mode composite");
  }
  gpu::GlContext& context = *device.context;
  // slice2d keeps its own slice stacks; the others sample a planned layout.
  Volume reduced;
  const Volume* volumeToRender = &fullVolume;
  std::unique_ptr<layout::Layout> layout;
  std::string layoutName = "slice-stacks";
  if (req.technique != "slice2d") {
    const render::RaycastPlan rp =
        render::planRaycast(device.limits, fullVolume, req.layout, req.width, req.height,
                            req.technique == "raycast" ? req.skipBlock : 0);
    req.skipBlock = rp.skipBlock;
    if (rp.plan.downsampled()) {
      reduced = lod::downsample(fullVolume, rp.plan.downsample);
      volumeToRender = &reduced;
    }
    layout = layout::createLayout(rp.plan, *volumeToRender, device.limits, context.ledger());
    layoutName = layout->name();
  }
  const Volume& volume = *volumeToRender;

  std::unique_ptr<render::Raycaster> caster;
  std::unique_ptr<render::Slice3DRenderer> slice3d;
  std::unique_ptr<render::Slice2DRenderer> slice2d;
  std::unique_ptr<render::HybridTechnique> technique;
  if (req.technique == "raycast") {
    caster = std::make_unique<render::Raycaster>(context, volume, *layout);
    caster->setSkipBlockSize(req.skipBlock);
    caster->setLutSize(req.lutSize);
    caster->setTransferFunction(tf);
    caster->prepare(req.settings);
    technique = std::make_unique<render::HybridRaycastTechnique>(*caster);
  } else if (req.technique == "slice3d") {
    slice3d = std::make_unique<render::Slice3DRenderer>(context, volume, *layout);
    slice3d->setSliceCount(req.slices);
    slice3d->setTransferFunction(tf);
    slice3d->prepare(req.settings);
    technique = std::make_unique<render::HybridSliceTechnique<render::Slice3DRenderer>>("slice3d",
                                                                                        *slice3d);
  } else if (req.technique == "slice2d") {
    slice2d = std::make_unique<render::Slice2DRenderer>(context, volume,
                                                        slice2dOptions(req, device.limits));
    slice2d->setSliceCount(req.slices);
    slice2d->setTransferFunction(tf);
    technique = std::make_unique<render::HybridSliceTechnique<render::Slice2DRenderer>>("slice2d",
                                                                                        *slice2d);
  } else {
    throw InputError("--technique '" + req.technique + "': expected raycast, slice3d or slice2d");
  }
  render::HybridCompositor compositor(context);
  compositor.setOverlayLines(render::overlayLines(volume, hybrid.overlays));
  req.camera.frame(volume);

  HybridResult result;
  result.layout = layoutName;
  result.technique = req.technique;
  for (int i = 0; i < req.repeat; ++i) {
    Camera cam = req.camera;
    cam.azimuthDeg += i * req.rotateDeg;
    const auto t0 = std::chrono::steady_clock::now();
    compositor.render(*technique, cam, req.settings, volume.extent(), req.width, req.height,
                      hybrid.hybrid);
    result.frameMs.push_back(msSince(t0));
    if (i == 0) {
      result.image = compositor.readImage();
      result.firstTimings = compositor.timings();
      if (req.reference) {
        const auto tRef = std::chrono::steady_clock::now();
        if (req.settings.mode == RenderMode::Composite) {
          result.groundTruth = renderReferenceWithLines(
              volume, tf, req.camera, req.settings, req.width, req.height,
              compositor.overlays().readColor(), compositor.overlays().readDistance());
        } else {
          result.groundTruth =
              renderReference(volume, tf, req.camera, req.settings, req.width, req.height);
        }
        result.groundTruthMs = msSince(tRef);
        result.psnrDb = psnr(result.image, *result.groundTruth);
        result.ssim = ssim(result.image, *result.groundTruth);
      }
    }
  }
  result.textureBytes = context.ledger().totalBytes();
  return result;
}

void printHybridResult(const HybridResult& r, const RenderRequest& req, const HybridRequest& h,
                       const DeviceSession& device, const std::string& spec, const std::string& out,
                       bool json) {
  std::vector<double> sorted = r.frameMs;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
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
                sorted.front(), sorted.back());
  }
  if (r.psnrDb) {
    std::printf(
        "ground truth %.0f ms on the CPU (full resolution, rays stop at the lines); PSNR %.2f dB, "
        "SSIM %.5f\n",
        r.groundTruthMs, *r.psnrDb, *r.ssim);
  }
}

}  // namespace tessera::app
