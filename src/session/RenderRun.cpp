#include "tessera/session/RenderRun.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/core/Timing.h"
#include "tessera/layout/StreamingLayout.h"
#include "tessera/lod/LevelScale.h"
#include "tessera/lod/ReadLevel.h"
#include "tessera/reference/CellLevels.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/reference/VoxelGradients.h"
#include "tessera/render/FusionTexture.h"
#include "tessera/render/TechniqueRegistry.h"

namespace tessera::session {

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

// Frame 0 of a streamed volume: draw, stream, upload, draw again until
// every brick the view wants is resident (progressive refinement while the
// view stays still), so the image written is the refined one.
void refineFirstFrame(layout::StreamingLayout& bricks, render::Technique& technique,
                      const TransferFunction& tf, const RenderRequest& req, BricksRun& run) {
  const Camera& camera = req.settings.camera;
  bool reported = false;
  const RefineRun r = BrickRefinement(bricks).refine(
      camera, req.width, req.height, tf,
      [&] { technique.render(camera, req.settings.render, req.width, req.height, 0.0); },
      req.refine,
      [&](const RefineRun& now, double ms) {
        reported = true;
        std::fprintf(stderr, "\rbricks: frame %d, %.0f s, %d of %d bricks missing (%d failing)   ",
                     now.frames, ms / 1000.0, now.last.missing, now.last.wanted, now.last.failing);
      });
  if (reported) std::fprintf(stderr, "\n");
  run.refineFrames = r.frames;
  run.firstFrameMs = r.firstFrameMs;
  run.completeMs = r.completeMs;
  run.complete = r.last.complete;
  run.failing = r.last.failing;
  run.failedReads = r.failedReads;
  run.failedReadCount = r.failedReadCount;
  run.wantedPerLevel = r.last.wantedPerLevel;
  run.cellsPerLevel = r.last.cellsPerLevel;
}

// The frames, rotating from the requested view; the first is kept. A
// bricked volume streams during the rotation: each frame selects, requests
// and uploads within the layout's per-frame budget, and that time counts.
void renderFrames(render::Technique& technique, layout::StreamingLayout* bricks,
                  const TransferFunction& tf, const RenderRequest& req, RenderResult& result) {
  for (int i = 0; i < req.repeat; ++i) {
    Camera cam = req.settings.camera;
    cam.azimuthDeg += i * req.rotateDeg;
    const auto t0 = std::chrono::steady_clock::now();
    if (bricks && i > 0) {
      const layout::BricksFrame f = bricks->update(cam, req.width, req.height, tf);
      result.bricks->rotatingLevels.push_back(levelsText(f.cellsPerLevel, true));
    }
    technique.render(cam, req.settings.render, req.width, req.height, 0.0);
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
                          const layout::ReferenceField& own, const TransferFunction& tf,
                          const RenderRequest& req, RenderResult& result) {
  const render::SamplingTwin twin = technique.samplingTwin(req.settings.render);
  const bool fine = req.referenceStep > 0.0;
  const std::optional<FusionTwin> fusionTwin =
      req.fusion
          ? std::optional<FusionTwin>(FusionTwin{
                *req.fusion, fusedFromAnatomy(own.box ? *own.box : volume, *req.fusion->volume)})
          : std::nullopt;
  const FusionTwin* fusion = fusionTwin ? &*fusionTwin : nullptr;
  const Camera& camera = req.settings.camera;
  RenderSettings settings = req.settings.render;
  if (fine) {
    settings.stepVoxels = req.referenceStep;
    settings.sampling = Sampling();
    // Enough steps for the whole ray at the fine step.
    settings.maxSteps =
        std::max(settings.maxSteps,
                 static_cast<int>(std::ceil(req.settings.render.maxSteps *
                                            req.settings.render.stepVoxels / req.referenceStep)));
  }
  const auto render = [&](const RenderSettings& s, const StepGrid* g, ReferenceStats* stats,
                          int width, int height) {
    if (own.ownField()) {
      return renderReference(*own.box, *own.field, tf, camera, s, width, height, 0, stats, nullptr,
                             g, fusion);
    }
    // The twin shades the field the GPU shaded: with a precomputed gradient
    // texture its quantised per-voxel differences; the fine reference keeps
    // the exact central differences (the truth the texture is judged by).
    if (!fine && twin.gradients != nullptr) {
      const TrilinearReconstruction values(volume);
      return renderReference(volume, VoxelGradientReconstruction(values, *twin.gradients), tf,
                             camera, s, width, height, 0, stats, nullptr, g, fusion);
    }
    return renderReference(volume, tf, camera, s, width, height, 0, stats, nullptr, g, fusion);
  };
  const auto t0 = std::chrono::steady_clock::now();
  ReferenceStats stats;
  result.referenceImage =
      render(settings, fine ? nullptr : twin.steps, &stats, req.width, req.height);
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

// The host memory the reference of a pyramid level takes: the level read
// whole (unless it is the in-core volume itself) and the double-precision
// copy its reconstruction keeps (reference/Reconstruction.h).
std::uint64_t referenceBytes(const lod::MultiresSource& pyramid, int level, bool held) {
  const std::uint64_t voxels =
      lod::levelBytes(pyramid, level) / bytesPerVoxel(pyramid.shape().type());
  return (held ? 0 : lod::levelBytes(pyramid, level)) + voxels * sizeof(double);
}

// The asked level exists, and its reference fits the host budget; else an
// error that names the level, its size and the budget and says which level
// would fit.
void checkReferenceLevel(const lod::MultiresSource& pyramid, int level, bool heldLevel0) {
  const int levels = pyramid.levelCount();
  const std::string range = "levels 0.." + std::to_string(levels - 1) + " (0 = the finest)";
  if (level < 0 || level >= levels) {
    throw InputError("--reference-level " + std::to_string(level) + ": " + pyramid.describe() +
                     " has " + range);
  }
  const std::uint64_t budget = HostBudget::global().limitBytes();
  const auto need = [&](int l) { return referenceBytes(pyramid, l, heldLevel0 && l == 0); };
  if (need(level) <= budget) return;
  int fits = level + 1;
  while (fits < levels && need(fits) > budget) ++fits;
  throw BudgetError(
      "the reference at " + lod::describeLevel(pyramid, level) + " of " + pyramid.describe() +
      " needs " + formatBytes(need(level)) +
      " of host memory (the level read whole and a double-precision copy), over the host budget "
      "of " +
      formatBytes(budget) + ": choose a coarser level with --reference-level N (" +
      (fits < levels ? "level " + std::to_string(fits) + " is the finest that fits" : "none fits") +
      "; the pyramid has levels 0.." + std::to_string(levels - 1) + ")");
}

// The levels a streamed frame shows, per level-0 brick cell (its page
// table as drawn): what the reference of that frame reads.
CellLevels shownCells(const layout::StreamingLayout& bricks) {
  const lod::BrickGrid& grid = bricks.grid();
  CellLevels cells;
  cells.finestDims = grid.dims(0);
  cells.brickSize = grid.brickSize();
  cells.cells = grid.bricks(0);
  cells.levels = bricks.cellLevels();
  return cells;
}

// The levels `cells` shows, finest first.
std::vector<int> levelsShown(const CellLevels& cells, int levels) {
  const std::vector<int> n = cells.cellsPerLevel();
  std::vector<int> shown;
  for (int l = 0; l < levels && l + 1 < static_cast<int>(n.size()); ++l) {
    if (n[static_cast<std::size_t>(l)] > 0) shown.push_back(l);
  }
  return shown;
}

// The levels of a mixed frame's reference fit the host budget together;
// else an error naming them, their size and the budget, and the finest
// single level that fits (--reference-level).
void checkShownLevels(const lod::MultiresSource& pyramid, const std::vector<int>& shown,
                      bool heldLevel0) {
  const std::uint64_t budget = HostBudget::global().limitBytes();
  const auto need = [&](int l) { return referenceBytes(pyramid, l, heldLevel0 && l == 0); };
  std::uint64_t total = 0;
  std::string names;
  for (int l : shown) {
    total += need(l);
    names += (names.empty() ? "" : ", ") + lod::describeLevel(pyramid, l);
  }
  if (total <= budget) return;
  const int levels = pyramid.levelCount();
  int fits = shown.front();
  while (fits < levels && need(fits) > budget) ++fits;
  throw BudgetError(
      "the reference of frame 0's levels (" + names + " of " + pyramid.describe() + ") needs " +
      formatBytes(total) +
      " of host memory (each level read whole and a double-precision copy), over the host budget "
      "of " +
      formatBytes(budget) + ": choose one level with --reference-level N (" +
      (fits < levels ? "level " + std::to_string(fits) + " is the finest that fits" : "none fits") +
      "; the pyramid has levels 0.." + std::to_string(levels - 1) + ")");
}

// Level `level` of a pyramid, as bricks.glsl samples it, over level 0's box:
// the in-core volume itself at level 0 when it is held.
std::shared_ptr<const Reconstruction> levelField(const lod::MultiresSource& pyramid,
                                                 const Volume& volume, int level, bool nearest) {
  const glm::ivec3 finest = pyramid.shape().dims();
  if (level == 0 && volume.hasData()) {
    return std::make_shared<PyramidLevelReconstruction>(volume, glm::ivec3(1), finest, nearest);
  }
  return std::make_shared<PyramidLevelReconstruction>(
      lod::readLevel(pyramid, level), lod::levelScale(pyramid, level), finest, nearest);
}

// The field the reference renders for one level of a streamed pyramid
// (--reference-level).
layout::ReferenceField streamedField(const lod::MultiresSource& pyramid, const Volume& volume,
                                     int level, const RenderRequest& req) {
  checkReferenceLevel(pyramid, level, volume.hasData());
  layout::ReferenceField field;
  field.box = &volume;
  field.field = levelField(pyramid, volume, level, req.settings.render.nearest);
  return field;
}

// The field frame 0 shows: in each level-0 cell the level its page table
// names (CellLevelsReconstruction), so a frame the atlas could not hold at
// level 0 everywhere is proven cell by cell; one level read when it shows
// one. Transparent cells (a constant the transfer function hides) read the
// finest level shown; a frame of transparent cells only, the coarsest.
layout::ReferenceField shownField(const lod::MultiresSource& pyramid, const Volume& volume,
                                  const CellLevels& cells, const BricksRun& run,
                                  const RenderRequest& req, RenderResult& result) {
  const int levels = pyramid.levelCount();
  const std::vector<int> shown = levelsShown(cells, levels);
  const std::string stopped = run.complete ? "" : " (refining stopped before it completed)";
  result.referenceLevelMixed = shown.size() > 1;
  result.referenceLevel = shown.empty() ? levels - 1 : shown.front();
  result.referenceLevelDims = pyramid.levelInfo(*result.referenceLevel).dims;
  if (shown.size() < 2) {
    result.referenceLevelNote =
        shown.empty()
            ? "frame 0 shows no brick (every cell is transparent): the coarsest level" + stopped
            : "the level frame 0 shows in every cell that is not transparent" + stopped;
    return streamedField(pyramid, volume, *result.referenceLevel, req);
  }
  checkShownLevels(pyramid, shown, volume.hasData());
  result.referenceLevelNote = "per cell, the level frame 0 shows there (page-table cells " +
                              levelsText(cells.cellsPerLevel(), true) + ")" + stopped;
  std::vector<std::shared_ptr<const Reconstruction>> fields(static_cast<std::size_t>(levels));
  for (int l : shown) {
    fields[static_cast<std::size_t>(l)] =
        levelField(pyramid, volume, l, req.settings.render.nearest);
  }
  layout::ReferenceField field;
  field.box = &volume;
  field.field = std::make_shared<CellLevelsReconstruction>(cells, std::move(fields), shown.front());
  return field;
}

}  // namespace

double RenderResult::median() const {
  return tessera::median(frameMs);
}
double RenderResult::min() const {
  return frameMs.empty() ? 0.0 : *std::min_element(frameMs.begin(), frameMs.end());
}
double RenderResult::max() const {
  return frameMs.empty() ? 0.0 : *std::max_element(frameMs.begin(), frameMs.end());
}

void prepareFrame(render::Technique& technique, const Volume& volume, RenderRequest& req) {
  technique.setTransferFunction(req.settings.tf);
  if (req.fusion) applyFusionSettings(req.settings.render);
  technique.setFusion(req.fusion);
  req.settings.camera.frame(volume);
  // Pre-integration and adaptive steps are the ray caster's; the slicers draw
  // planes, and their reference must not assume either.
  const render::TechniqueEntry& entry =
      render::TechniqueRegistry::global().find(req.settings.technique);
  if (!entry.honoursSampling) req.settings.render.sampling = Sampling();
  technique.prepare(req.settings.camera, req.settings.render);
}

void applyFusionSettings(RenderSettings& s) {
  const std::string why = "a fused volume (--overlay) is mixed into composite samples";
  if (s.mode != RenderMode::Composite) throw InputError(why + ": use --mode composite");
  if (s.shading.gradientOpacity) throw InputError(why + ": without --gradient-opacity");
  s.sampling = Sampling();  // every sample, post-classified (docs/fusion.md)
}

void checkImageSize(int width, int height) {
  if (width < 1 || height < 1 || width > 16384 || height > 16384) {
    throw InputError("size " + std::to_string(width) + "x" + std::to_string(height) +
                     ": width and height must be 1..16384");
  }
}

RenderResult runRender(gpu::DeviceSession& device, const lod::VolumeSource& source,
                       RenderRequest req) {
  req.settings.validate();
  if (req.repeat < 1) throw InputError("repeat " + std::to_string(req.repeat) + ": expected >= 1");
  checkImageSize(req.width, req.height);
  if (req.referenceLevel && !req.reference) {
    throw InputError("--reference-level needs the reference (--reference)");
  }
  if (req.fusion) render::FusionTexture::checkDevice(device.limits, *req.fusion);
  const Settings& s = req.settings;
  render::TechniqueOnVolume t = render::createTechnique(s.technique, *device.context, device.limits,
                                                        source, req.techniqueOptions(), s.layout);
  // An asked level is checked before the frames are drawn.
  if (req.referenceLevel) {
    if (!t.upload.pyramid) {
      throw InputError("--reference-level applies to a layout that streams a pyramid (bricks); " +
                       t.storageName() + " holds the volume it renders, which the reference reads");
    }
    checkReferenceLevel(*t.upload.pyramid, *req.referenceLevel, t.upload.volume->hasData());
  }
  const Volume& volume = *t.upload.volume;
  const TransferFunction& tf = s.tf;
  RenderResult result;
  const auto tPrepare = std::chrono::steady_clock::now();
  prepareFrame(*t.technique, volume, req);
  result.prepareMs = msSince(tPrepare);
  layout::StreamingLayout* bricks = t.upload.layout ? t.upload.layout->streaming() : nullptr;
  CellLevels frame0Cells;  // what frame 0 shows, before --repeat's frames stream on
  if (bricks) {
    result.bricks.emplace();
    refineFirstFrame(*bricks, *t.technique, tf, req, *result.bricks);
    frame0Cells = shownCells(*bricks);
  }
  renderFrames(*t.technique, bricks, tf, req, result);
  result.textureBytes = device.context->ledger().totalBytes();  // while the technique holds its own
  const render::SamplingTwin twin = t.technique->samplingTwin(req.settings.render);
  result.preintegrated = twin.preintegrated;
  result.adaptive = twin.steps != nullptr;
  result.preintegrationBuildMs = twin.preintegrationBuildMs;
  result.preintegrationUploadMs = twin.preintegrationUploadMs;
  describeStorage(t, result);
  if (bricks) {
    const lod::StreamerStats stats = bricks->streamerStats();
    result.bricks->slots = bricks->slotCount();
    result.bricks->bytesRead = stats.bytesRead;
    result.bricks->bricksRead = stats.bricksRead;
    result.bricks->readErrors = stats.readErrors;
    result.bricks->cachePeakBytes = stats.cachePeakBytes;
    result.bricks->lastError = stats.lastError;
  }
  if (req.reference) {
    layout::ReferenceField field;
    if (t.upload.pyramid) {
      const lod::MultiresSource& pyramid = *t.upload.pyramid;
      if (result.bricks && !req.referenceLevel) {
        field = shownField(pyramid, volume, frame0Cells, *result.bricks, req, result);
      } else {
        const int level = req.referenceLevel.value_or(0);
        result.referenceLevelNote = req.referenceLevel ? "asked for (--reference-level)" : "";
        field = streamedField(pyramid, volume, level, req);
        result.referenceLevel = level;
        result.referenceLevelDims = pyramid.levelInfo(level).dims;
      }
    } else if (t.upload.layout) {
      field = t.upload.layout->referenceField();
    }
    compareWithReference(volume, *t.technique, field, tf, req, result);
  }
  return result;
}

}  // namespace tessera::session
