#pragma once
// `tessera render` with overlays and/or a reduced offscreen size: the hybrid
// low/high-resolution compositor (render/HybridCompositor.h) driven from the
// command line, with the CPU ground truth (volume and lines at full
// resolution, correct occlusion) on request.
#include <optional>
#include <string>

#include "tessera/gpu/DeviceSession.h"
#include "tessera/render/HybridCompositor.h"
#include "tessera/render/Overlay.h"
#include "tessera/session/RenderRun.h"

namespace tessera::app {

using gpu::DeviceSession;
using session::RenderRequest;

struct HybridRequest {
  render::OverlayOptions overlays;
  render::HybridOptions hybrid;
};

struct HybridResult {
  Image image;
  std::vector<double> frameMs;
  render::HybridTimings firstTimings;
  std::optional<Image> groundTruth;
  double groundTruthMs = 0.0;
  std::optional<double> psnrDb;
  std::optional<double> ssim;
  std::string technique;
  std::string layout;
  std::uint64_t textureBytes = 0;
};

HybridResult runHybridRender(DeviceSession& device, const lod::VolumeSource& source,
                             RenderRequest request, const HybridRequest& hybrid);

// The render command's output for a hybrid run (text or JSON).
void printHybridResult(const HybridResult& r, const RenderRequest& request,
                       const HybridRequest& hybrid, const DeviceSession& device,
                       const std::string& spec, const std::string& out, bool json);

}  // namespace tessera::app
