#include "app/RenderJob.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "tessera/core/Error.h"
#include "tessera/core/Timing.h"
#include "tessera/lattice/BoxSplineReconstruction.h"
#include "tessera/layout/BricksLayout.h"
#include "tessera/layout/FccLayout.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/reference/VoxelGradients.h"
#include "tessera/render/Raycaster.h"
#include "tessera/render/TechniqueRegistry.h"

namespace tessera::app {

namespace {

std::string levelsText(const std::vector<int>& perLevel, bool lastIsTransparent) {
  std::string s;
  for (std::size_t l = 0; l < perLevel.size(); ++l) {
    if (perLevel[l] == 0) continue;
    const bool empty = lastIsTransparent && l + 1 == perLevel.size();
    char item[48];
    if (empty) {
      std::snprintf(item, sizeof item, "%sempty:%d", s.empty() ? "" : " ", perLevel[l]);
    } else {
      std::snprintf(item, sizeof item, "%sL%zu:%d", s.empty() ? "" : " ", l, perLevel[l]);
    }
    s += item;
  }
  return s;
}

// Frame 0 of a bricked volume: draw, stream, upload, draw again until every
// brick the view wants is resident (progressive refinement while the view
// stays still), so the image written is the refined one.
void refineBricks(layout::BricksLayout& bricks, render::Technique& technique,
                  const TransferFunction& tf, const RenderRequest& req, BricksRun& run) {
  const auto t0 = std::chrono::steady_clock::now();
  layout::BricksFrame f;
  double lastReportMs = 0.0;
  bool reported = false;
  while (true) {
    f = bricks.update(req.camera, req.width, req.height, tf);
    technique.render(req.camera, req.settings, req.width, req.height, 0.0);
    if (++run.refineFrames == 1) run.firstFrameMs = msSince(t0);
    if (f.complete || run.refineFrames >= req.maxRefineFrames ||
        msSince(t0) > 1000.0 * req.maxRefineSeconds) {
      break;
    }
    if (f.uploaded == 0) bricks.waitForBricks(50.0);
    if (msSince(t0) - lastReportMs > 1000.0) {  // progress, once a second
      lastReportMs = msSince(t0);
      reported = true;
      std::fprintf(stderr, "\rbricks: frame %d, %.0f s, %d of %d bricks missing   ",
                   run.refineFrames, lastReportMs / 1000.0, f.missing, f.wanted);
    }
  }
  if (reported) std::fprintf(stderr, "\n");
  run.completeMs = msSince(t0);
  run.complete = f.complete;
  run.failing = f.failing;
  run.wantedPerLevel = f.wantedPerLevel;
  run.cellsPerLevel = f.cellsPerLevel;
}

// The frames, rotating from the requested view; the first is kept. A
// bricked volume streams during the rotation: each frame selects, requests
// and uploads within the layout's per-frame budget, and that time counts.
void renderFrames(render::Technique& technique, layout::BricksLayout* bricks,
                  const TransferFunction& tf, const RenderRequest& req, RenderResult& result) {
  for (int i = 0; i < req.repeat; ++i) {
    Camera cam = req.camera;
    cam.azimuthDeg += i * req.rotateDeg;
    const auto t0 = std::chrono::steady_clock::now();
    if (bricks && i > 0) {
      const layout::BricksFrame f = bricks->update(cam, req.width, req.height, tf);
      result.bricks->rotatingLevels.push_back(levelsText(f.cellsPerLevel, true));
    }
    technique.render(cam, req.settings, req.width, req.height, 0.0);
    result.frameMs.push_back(msSince(t0));
    if (i == 0) result.first = technique.readImage();
  }
}

// Where the volume lived and what the technique did, for the report.
void describeStorage(const render::TechniqueOnVolume& t, RenderResult& result) {
  const render::TechniqueReport report = t.technique->report();
  result.plan = t.upload.plan;
  result.renderedDims = t.upload.volume->dims();
  result.layout = t.storageName();
  result.layoutReason = t.upload.layout ? t.upload.plan.reason : report.storageReason;
  result.volumeTextureBytes =
      t.upload.layout ? t.upload.layout->textureBytes() : report.storageBytes;
  result.planNote = t.requirements.note;
  if (!report.note.empty()) result.planNote += (result.planNote.empty() ? "" : "; ") + report.note;
  result.occupiedBlockFraction = report.occupiedBlockFraction;
  result.gradient = report.gradient;
}

// Frame 0 against the CPU reference of the volume the GPU rendered: its
// voxels through trilinear interpolation, or an FCC layout's lattice through
// the box spline. The twin (no --reference-step) takes the render's own
// samples: the ray caster's block grid when it steps adaptively. With
// --reference-step the reference is the fine truth: that step, every sample,
// post-classified.
void compareWithReference(const Volume& volume, const render::Technique& technique,
                          const layout::Layout* layout, const TransferFunction& tf,
                          const RenderRequest& req, RenderResult& result) {
  const auto* caster = dynamic_cast<const render::Raycaster*>(&technique);
  const StepGrid* grid =
      caster != nullptr && caster->stepGrid().valid() && usesAdaptiveSampling(req.settings)
          ? &caster->stepGrid()
          : nullptr;
  const bool fine = req.referenceStep > 0.0;
  RenderSettings settings = req.settings;
  if (fine) {
    settings.stepVoxels = req.referenceStep;
    settings.sampling = Sampling();
    // Enough steps for the whole ray at the fine step.
    settings.maxSteps =
        std::max(settings.maxSteps,
                 static_cast<int>(std::ceil(req.settings.maxSteps * req.settings.stepVoxels /
                                            req.referenceStep)));
  }
  const auto render = [&](const RenderSettings& s, const StepGrid* g, ReferenceStats* stats,
                          int width, int height) {
    if (const auto* fcc = dynamic_cast<const layout::FccLayout*>(layout)) {
      return renderReference(fcc->lattice().box(), lattice::BoxSplineReconstruction(fcc->lattice()),
                             tf, req.camera, s, width, height, 0, stats, nullptr, g);
    }
    // The twin shades the field the GPU shaded: with a precomputed gradient
    // texture its quantised per-voxel differences; the fine reference keeps
    // the exact central differences (the truth the texture is judged by).
    if (!fine && caster != nullptr && caster->precomputedGradient(req.settings)) {
      const TrilinearReconstruction values(volume);
      return renderReference(
          volume, VoxelGradientReconstruction(values, caster->gradientTexture().gradients()), tf,
          req.camera, s, width, height, 0, stats, nullptr, g);
    }
    return renderReference(volume, tf, req.camera, s, width, height, 0, stats, nullptr, g);
  };
  const auto t0 = std::chrono::steady_clock::now();
  ReferenceStats stats;
  result.referenceImage = render(settings, fine ? nullptr : grid, &stats, req.width, req.height);
  result.referenceMs = msSince(t0);
  result.referenceSamples = stats.samples;
  result.referenceRays = stats.raysHittingVolume;
  result.referenceStep = settings.stepVoxels;
  result.psnrDb = psnr(result.first, *result.referenceImage);
  result.ssim = ssim(result.first, *result.referenceImage);
  if (!fine) {
    result.samplesPerRay =
        stats.raysHittingVolume
            ? static_cast<double>(stats.samples) / static_cast<double>(stats.raysHittingVolume)
            : 0.0;
  }
}

}  // namespace

render::TechniqueOptions RenderRequest::techniqueOptions() const {
  return {.imageSize = {width, height},
          .skipBlock = skipBlock,
          .lutSize = lutSize,
          .slices = slices,
          .classify = classify,
          .gradient = gradient};
}

double RenderResult::median() const {
  return tessera::median(frameMs);
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

RenderResult runRender(DeviceSession& device, const lod::VolumeSource& source,
                       const TransferFunction& tf, RenderRequest req) {
  if (req.repeat < 1) throw InputError("--repeat must be >= 1");
  if (req.slices < 0) throw InputError("--slices must be >= 1 (0 = automatic)");
  render::TechniqueOnVolume t = render::createTechnique(
      req.technique, *device.context, device.limits, source, req.techniqueOptions(), req.layout);
  const Volume& volume = *t.upload.volume;
  RenderResult result;
  t.technique->setTransferFunction(tf);
  req.camera.frame(volume);
  // Pre-integration and adaptive steps are the ray caster's; the slicers draw
  // planes, and their reference must not assume either.
  auto* caster = dynamic_cast<render::Raycaster*>(t.technique.get());
  if (caster == nullptr) req.settings.sampling = Sampling();
  const auto tPrepare = std::chrono::steady_clock::now();
  t.technique->prepare(req.camera, req.settings);
  result.prepareMs = msSince(tPrepare);
  auto* bricks = dynamic_cast<layout::BricksLayout*>(t.upload.layout.get());
  if (bricks) {
    result.bricks.emplace();
    refineBricks(*bricks, *t.technique, tf, req, *result.bricks);
  }
  renderFrames(*t.technique, bricks, tf, req, result);
  result.textureBytes = device.context->ledger().totalBytes();  // while the technique holds its own
  result.preintegrated = caster != nullptr && usesPreintegration(req.settings);
  result.adaptive =
      caster != nullptr && usesAdaptiveSampling(req.settings) && caster->stepGrid().valid();
  if (result.preintegrated) {
    result.preintegrationBuildMs = caster->preintegrationTable().lastBuildMs();
    result.preintegrationUploadMs = caster->preintegrationTable().lastUploadMs();
  }
  describeStorage(t, result);
  if (bricks) {
    const lod::StreamerStats s = bricks->streamerStats();
    result.bricks->slots = bricks->slotCount();
    result.bricks->bytesRead = s.bytesRead;
    result.bricks->bricksRead = s.bricksRead;
    result.bricks->readErrors = s.readErrors;
    result.bricks->cachePeakBytes = s.cachePeakBytes;
    result.bricks->lastError = s.lastError;
  }
  if (req.reference) {
    if (!volume.hasData()) {
      throw InputError("--reference needs the volume in host memory; " + result.layout +
                       " streams it");
    }
    compareWithReference(volume, *t.technique, t.upload.layout.get(), tf, req, result);
  }
  return result;
}

}  // namespace tessera::app
