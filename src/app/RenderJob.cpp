#include "app/RenderJob.h"

#include <algorithm>
#include <chrono>

#include <glm/vec3.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/lod/Downsample.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/Raycaster.h"

namespace tessera::app {

namespace {
double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

double RenderResult::median() const {
  if (frameMs.empty()) return 0.0;
  std::vector<double> v = frameMs;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
double RenderResult::min() const {
  return frameMs.empty() ? 0.0 : *std::min_element(frameMs.begin(), frameMs.end());
}
double RenderResult::max() const {
  return frameMs.empty() ? 0.0 : *std::max_element(frameMs.begin(), frameMs.end());
}

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

RenderResult runRender(DeviceSession& device, const Volume& fullVolume, const TransferFunction& tf,
                       RenderRequest req) {
  if (req.repeat < 1) throw InputError("--repeat must be >= 1");
  if (req.technique != "raycast") return runSliceRender(device, fullVolume, tf, req);
  gpu::GlContext& context = *device.context;
  RenderResult result;
  const render::RaycastPlan rp = render::planRaycast(device.limits, fullVolume, req.layout,
                                                     req.width, req.height, req.skipBlock);
  result.plan = rp.plan;
  result.planNote = rp.note;
  req.skipBlock = rp.skipBlock;
  Volume reduced;
  if (result.plan.downsampled()) reduced = lod::downsample(fullVolume, result.plan.downsample);
  const Volume& volume = result.plan.downsampled() ? reduced : fullVolume;
  result.renderedDims = volume.dims();
  auto layout = layout::createLayout(result.plan, volume, device.limits, context.ledger());
  result.layout = layout->name();
  result.layoutReason = result.plan.reason;
  result.volumeTextureBytes = layout->textureBytes();

  render::Raycaster caster(context, volume, *layout);
  caster.setSkipBlockSize(req.skipBlock);
  caster.setLutSize(req.lutSize);
  caster.setTransferFunction(tf);
  req.camera.frame(volume);
  const auto tPrepare = std::chrono::steady_clock::now();
  caster.prepare(req.settings);
  result.prepareMs = msSince(tPrepare);
  result.occupiedBlockFraction = caster.occupiedBlockFraction();

  for (int i = 0; i < req.repeat; ++i) {
    Camera cam = req.camera;
    cam.azimuthDeg += i * req.rotateDeg;
    const auto t0 = std::chrono::steady_clock::now();
    caster.renderFrame(cam, req.settings, req.width, req.height);
    result.frameMs.push_back(msSince(t0));
    if (i == 0) result.first = caster.readImage();
  }
  result.textureBytes = context.ledger().totalBytes();

  if (req.reference) {
    const auto t0 = std::chrono::steady_clock::now();
    ReferenceStats stats;
    result.referenceImage =
        renderReference(volume, tf, req.camera, req.settings, req.width, req.height, 0, &stats);
    result.referenceSamples = stats.samples;
    result.referenceRays = stats.raysHittingVolume;
    result.referenceMs = msSince(t0);
    result.psnrDb = psnr(result.first, *result.referenceImage);
    result.ssim = ssim(result.first, *result.referenceImage);
  }
  return result;
}

}  // namespace tessera::app
