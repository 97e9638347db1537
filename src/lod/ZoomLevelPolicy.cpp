#include "tessera/lod/ZoomLevelPolicy.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "tessera/core/Error.h"

namespace tessera::lod {

ZoomLevelPolicy::ZoomLevelPolicy(std::vector<ZoomStage> stages, ZoomPolicyOptions options)
    : stages_(std::move(stages)), options_(options) {
  if (stages_.empty()) throw InputError("zoom policy: no stages");
  if (!(options_.hysteresis > 0.0 && options_.hysteresis <= 1.0) || !(options_.fadeMs >= 0.0)) {
    throw InputError("zoom policy: hysteresis must be in (0, 1] and the fade time >= 0");
  }
  for (std::size_t s = 1; s < stages_.size(); ++s) {
    if (!(stages_[s].enterZoom > stages_[s - 1].enterZoom)) {
      throw InputError("zoom policy: stage '" + stages_[s].name +
                       "' must start at a larger zoom than '" + stages_[s - 1].name + "'");
    }
  }
}

std::vector<ZoomStage> ZoomLevelPolicy::overviewStages(int coarseLevel, int mediumLevel,
                                                       double pixelsPerVoxelAtZoom1,
                                                       double volumeRadius, double blockRadius,
                                                       const ZoomPolicyOptions& options,
                                                       const std::vector<double>& levelVoxels) {
  if (!(pixelsPerVoxelAtZoom1 > 0.0) || mediumLevel < 0 || coarseLevel < mediumLevel) {
    throw InputError("zoom policy: need coarse level >= medium level >= 0 and a positive view");
  }
  if (!levelVoxels.empty() && static_cast<int>(levelVoxels.size()) <= coarseLevel) {
    throw InputError("zoom policy: voxel scales for " + std::to_string(levelVoxels.size()) +
                     " levels, level " + std::to_string(coarseLevel) + " asked for");
  }
  // The zoom at which a voxel of `level` covers refineAbove pixels.
  auto magnified = [&](int level) {
    const double voxels = levelVoxels.empty() ? std::ldexp(1.0, level) : levelVoxels[level];
    return options.refineAbove / (voxels * pixelsPerVoxelAtZoom1);
  };
  std::vector<ZoomStage> stages;
  if (coarseLevel > mediumLevel) stages.push_back({"coarse", coarseLevel, false, 0.0});
  stages.push_back({"medium", mediumLevel, false, stages.empty() ? 0.0 : magnified(coarseLevel)});
  if (mediumLevel > 0 && blockRadius > 0.0 && volumeRadius > 0.0) {
    const double enter = std::max(magnified(mediumLevel), volumeRadius / blockRadius);
    stages.push_back({"native", 0, true, std::max(enter, stages.back().enterZoom * 1.001)});
  }
  return stages;
}

int ZoomLevelPolicy::stageFor(int current, double zoom) const {
  int s = std::clamp(current, 0, static_cast<int>(stages_.size()) - 1);
  while (s + 1 < static_cast<int>(stages_.size()) && zoom >= stages_[s + 1].enterZoom) ++s;
  while (s > 0 && zoom < stages_[s].enterZoom * options_.hysteresis) --s;
  return s;
}

ZoomFrame ZoomLevelPolicy::update(double zoom, double dtMs, const std::vector<bool>* resident) {
  auto isResident = [&](int s) {
    return !resident || (s < static_cast<int>(resident->size()) && (*resident)[s]);
  };
  ZoomFrame& f = frame_;
  if (!started_) {
    // The first frame shows what the zoom asks for; with nothing before it
    // there is nothing to fade from.
    started_ = true;
    f.stage = f.from = f.target = stageFor(0, zoom);
    f.mix = 1.0;
    f.waiting = false;
    return f;
  }
  const double step = options_.fadeMs > 0.0 ? std::max(0.0, dtMs) / options_.fadeMs : 1.0;
  const bool fading = f.from != f.stage;
  if (fading) {
    f.mix = std::min(1.0, f.mix + step);
    if (f.mix >= 1.0) f.from = f.stage;
  }
  f.target = stageFor(f.stage, zoom);
  if (f.target == f.stage) {
    f.waiting = false;
    return f;
  }
  if (f.from != f.stage) {
    // Mid-fade: going back reverses the fade from where it is.
    if (f.target == f.from) {
      std::swap(f.from, f.stage);
      f.mix = 1.0 - f.mix;
      f.waiting = false;
    }
    return f;  // anything else waits for the fade to end
  }
  if (!isResident(f.target)) {
    f.waiting = true;  // keep the current stage fully on screen
    return f;
  }
  f.waiting = false;
  f.from = f.stage;
  f.stage = f.target;
  f.mix = options_.fadeMs > 0.0 ? 0.0 : 1.0;
  if (f.mix >= 1.0) f.from = f.stage;
  return f;
}

}  // namespace tessera::lod
