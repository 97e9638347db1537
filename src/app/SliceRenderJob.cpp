// `tessera render --technique slice3d|slice2d`: the texture-slicing
// techniques of issue 4 behind the same RenderRequest/RenderResult as the
// ray caster, so timings, PSNR/SSIM and JSON output are shared.
#include <chrono>

#include "app/RenderJob.h"
#include "tessera/core/Error.h"
#include "tessera/lod/Downsample.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/Slice2DRenderer.h"
#include "tessera/render/Slice3DRenderer.h"

namespace tessera::app {

namespace {

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Frames of either technique, then the optional reference comparison.
template <class Renderer, class Prepare>
void renderFrames(Renderer& renderer, Prepare prepare, const Volume& volume,
                  const TransferFunction& tf, RenderRequest& req, RenderResult& result) {
  renderer.setTransferFunction(tf);
  req.camera.frame(volume);
  const auto tPrepare = std::chrono::steady_clock::now();
  prepare();
  result.prepareMs = msSince(tPrepare);
  for (int i = 0; i < req.repeat; ++i) {
    Camera cam = req.camera;
    cam.azimuthDeg += i * req.rotateDeg;
    const auto t0 = std::chrono::steady_clock::now();
    renderer.renderFrame(cam, req.settings, req.width, req.height);
    result.frameMs.push_back(msSince(t0));
    if (i == 0) result.first = renderer.readImage();
  }
}

}  // namespace

render::Slice2DOptions slice2dOptions(const RenderRequest& req, const gpu::DeviceLimits& limits) {
  if (req.layout != "auto") {
    throw InputError("--layout does not apply to slice2d: it stores its own slice stacks");
  }
  render::Slice2DOptions options;
  options.classification = render::parseSliceClassification(req.classify);
  options.maxTextureSize = limits.max2DTextureSize;
  return options;
}

RenderResult runSliceRender(DeviceSession& device, const Volume& fullVolume,
                            const TransferFunction& tf, RenderRequest req) {
  if (req.technique != "slice3d" && req.technique != "slice2d") {
    throw InputError("--technique '" + req.technique + "': expected raycast, slice3d or slice2d");
  }
  if (req.slices < 0) throw InputError("--slices must be >= 1 (0 = automatic)");
  gpu::GlContext& context = *device.context;
  RenderResult result;
  Volume reduced;
  const Volume* volume = &fullVolume;
  std::unique_ptr<layout::Layout> layout;
  if (req.technique == "slice3d") {
    // The ray caster's plan without its empty-space grid: the same layout
    // choice, one unit for the TF table.
    const render::RaycastPlan rp =
        render::planRaycast(device.limits, fullVolume, req.layout, req.width, req.height, 0);
    result.plan = rp.plan;
    result.planNote = rp.note;
    if (result.plan.downsampled()) {
      reduced = lod::downsample(fullVolume, result.plan.downsample);
      volume = &reduced;
    }
    layout = layout::createLayout(result.plan, *volume, device.limits, context.ledger());
    result.layout = layout->name();
    result.layoutReason = result.plan.reason;
    result.volumeTextureBytes = layout->textureBytes();
    render::Slice3DRenderer renderer(context, *volume, *layout);
    renderer.setSliceCount(req.slices);
    renderFrames(
        renderer, [&] { renderer.prepare(req.settings); }, *volume, tf, req, result);
    result.textureBytes = context.ledger().totalBytes();  // while the renderer holds its own
    result.planNote += (result.planNote.empty() ? "" : "; ") + std::string("slice3d: ") +
                       std::to_string(renderer.sliceCountFor(req.settings)) +
                       " view-aligned slices, accumulation " + renderer.accumulationFormat() +
                       ", no early termination";
  } else {
    const render::Slice2DOptions options = slice2dOptions(req, device.limits);
    render::Slice2DRenderer renderer(context, *volume, options);
    renderer.setSliceCount(req.slices);
    renderFrames(
        renderer, [&] { renderer.prepare(req.camera, req.settings); }, *volume, tf, req, result);
    result.textureBytes = context.ledger().totalBytes();
    const int axis = renderer.lastStackAxis();
    result.layout = "slice-stacks";
    result.layoutReason = "three axis-aligned stacks; drawn: " + std::string(1, "xyz"[axis]) +
                          " stack, " + renderer.atlasPlan(axis).describe() + ", " +
                          render::sliceClassificationName(options.classification) + "-classified";
    result.volumeTextureBytes = renderer.stackTextureBytes();
    result.planNote = "slice2d: " + std::to_string(renderer.slicesDrawn()) +
                      " slices drawn, accumulation " + renderer.accumulationFormat();
  }
  result.renderedDims = volume->dims();

  if (req.reference) {
    const auto t0 = std::chrono::steady_clock::now();
    ReferenceStats stats;
    result.referenceImage =
        renderReference(*volume, tf, req.camera, req.settings, req.width, req.height, 0, &stats);
    result.referenceSamples = stats.samples;
    result.referenceRays = stats.raysHittingVolume;
    result.referenceMs = msSince(t0);
    result.psnrDb = psnr(result.first, *result.referenceImage);
    result.ssim = ssim(result.first, *result.referenceImage);
  }
  return result;
}

}  // namespace tessera::app
