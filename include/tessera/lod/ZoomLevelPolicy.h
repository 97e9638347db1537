#pragma once
// Which version of a large volume the overview shows at a given zoom
// (Schultz 2016 §7.3.1: a coarse and a medium downsampled copy, swapped by
// zoom thresholds, and the native-resolution grid view once the user is
// close enough), with hysteresis so that a zoom resting near a threshold
// does not swap back and forth, and a cross-fade so that a swap never pops.
//
// Thresholds (documented in docs/explore.md):
//  - overview level l+1 -> l (finer): when a voxel of level l+1 covers more
//    than `refineAbove` pixels (default 1: the screen could show more than
//    the coarse copy holds). At zoom z a level-0 voxel covers
//    z * pixelsPerVoxelAtZoom1 pixels, a level-l voxel 2^l times that, so
//    the stage's enter zoom is refineAbove / (2^(l+1) pixelsPerVoxelAtZoom1).
//  - medium -> native sub-volume: when the view shows no more than the
//    grid's 2x2x2 block: the camera frames the volume's bounding sphere at
//    zoom 1, so at zoom z it frames a sphere of volumeRadius / z; the block
//    fills it from z = volumeRadius / blockRadius. (Also no earlier than the
//    medium level's voxels are magnified, by the rule above.)
//  - back to the coarser stage only below `hysteresis` (default 0.8) times
//    the enter zoom.
// Cross-fade: a swap waits until the new stage's data is resident (the old
// stage stays on screen meanwhile: refine in place), then blends the two
// images over `fadeMs`; the weight of the new one rises linearly with time.
// A swap back during a fade reverses it from where it is (no jump); any
// other change waits for the fade to end.
#include <string>
#include <vector>

namespace tessera::lod {

struct ZoomStage {
  std::string name;        // "coarse", "medium", "native"
  int level = 0;           // pyramid level shown
  bool subVolume = false;  // the grid view's block at native resolution, not the whole volume
  double enterZoom = 0.0;  // shown from this zoom up (the coarsest stage: 0)
};

struct ZoomPolicyOptions {
  double refineAbove = 1.0;  // pixels per voxel of the coarser stage
  double hysteresis = 0.8;   // leave a stage below this fraction of its enter zoom
  double fadeMs = 250.0;
};

// What to draw this frame: `stage`, blended over `from` with weight `mix`
// (1: only `stage`). `from` == `stage` when no fade is running.
struct ZoomFrame {
  int stage = 0;
  int from = 0;
  double mix = 1.0;
  bool waiting = false;  // the target stage is not resident yet: `stage` is the old one
  int target = 0;        // the stage the zoom asks for
};

class ZoomLevelPolicy {
 public:
  // Stages from coarsest to finest with increasing enter zooms.
  // InputError if empty or not increasing.
  ZoomLevelPolicy(std::vector<ZoomStage> stages, ZoomPolicyOptions options = {});

  // The paper's three stages: overview `coarseLevel` and `mediumLevel`
  // (mediumLevel < coarseLevel; the finest level that fits the budget) and,
  // when mediumLevel > 0, the native block. `pixelsPerVoxelAtZoom1`: screen
  // pixels per level-0 voxel at zoom 1 (view height / volume diagonal in
  // voxels); blockRadius / volumeRadius: half diagonals (any same unit).
  // `levelVoxels[l]`: level-0 voxels per level-l voxel along its most
  // reduced axis (the largest component of lod::levelScale): 1, 2, 4 for a
  // pyramid halving every axis; 1, 2, 2 for one whose levels keep z and
  // halve x and y. Empty: 2^l.
  static std::vector<ZoomStage> overviewStages(int coarseLevel, int mediumLevel,
                                               double pixelsPerVoxelAtZoom1, double volumeRadius,
                                               double blockRadius,
                                               const ZoomPolicyOptions& options = {},
                                               const std::vector<double>& levelVoxels = {});

  const std::vector<ZoomStage>& stages() const { return stages_; }
  const ZoomPolicyOptions& options() const { return options_; }

  // The hysteresis rule alone: the stage to show at `zoom` when `current` is
  // shown (may skip stages on a large jump).
  int stageFor(int current, double zoom) const;

  // One frame: the zoom now, the time since the last frame, and whether a
  // stage's data is resident (null: always).
  ZoomFrame update(double zoom, double dtMs, const std::vector<bool>* resident = nullptr);
  const ZoomFrame& frame() const { return frame_; }

 private:
  std::vector<ZoomStage> stages_;
  ZoomPolicyOptions options_;
  ZoomFrame frame_;
  bool started_ = false;
};

}  // namespace tessera::lod
