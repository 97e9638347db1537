// The zoom-driven level swap (Schultz 2016 §7.3.1): documented thresholds,
// hysteresis near a threshold, and a cross-fade without a jump that waits
// for the new stage's data.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "tessera/core/Error.h"
#include "tessera/lod/ZoomLevelPolicy.h"

using namespace tessera;
using namespace tessera::lod;

TEST(ZoomLevelPolicy, OverviewStagesFollowTheDocumentedThresholds) {
  // 512x512x894: diagonal ~1150 voxels on a 800-pixel view.
  const double diag = std::sqrt(512.0 * 512 + 512.0 * 512 + 894.0 * 894);
  const double k = 800.0 / diag;
  const auto stages = ZoomLevelPolicy::overviewStages(2, 1, k, diag / 2, diag / 4);
  ASSERT_EQ(stages.size(), 3u);
  EXPECT_EQ(stages[0].level, 2);
  EXPECT_EQ(stages[1].level, 1);
  EXPECT_TRUE(stages[2].subVolume);
  // medium from the zoom where a level-2 voxel covers one pixel
  EXPECT_NEAR(stages[1].enterZoom, 1.0 / (4.0 * k), 1e-12);
  // native from the zoom where the view shows no more than the half-size block
  EXPECT_NEAR(stages[2].enterZoom, std::max(2.0, 1.0 / (2.0 * k)), 1e-12);
  // The whole volume fits the budget (medium = level 0): no sub-volume stage.
  EXPECT_EQ(ZoomLevelPolicy::overviewStages(1, 0, k, diag / 2, diag / 4).size(), 2u);
}

TEST(ZoomLevelPolicy, ThresholdsFollowEachLevelsOwnScale) {
  // A (1, 2, 2) pyramid with z halved from level 2 on: level scales
  // (1,1,1), (1,2,2), (2,4,4) -> 1, 2, 4 voxels on the most reduced axis,
  // the same thresholds as halving; one keeping z and x: 1, 2, 2.
  const double diag = std::sqrt(512.0 * 512 + 512.0 * 512 + 64.0 * 64);
  const double k = 800.0 / diag;
  const auto halving = ZoomLevelPolicy::overviewStages(2, 1, k, diag / 2, diag / 4);
  const auto same = ZoomLevelPolicy::overviewStages(2, 1, k, diag / 2, diag / 4, {}, {1, 2, 4});
  ASSERT_EQ(same.size(), halving.size());
  for (std::size_t s = 0; s < same.size(); ++s) EXPECT_EQ(same[s].enterZoom, halving[s].enterZoom);
  const auto kept = ZoomLevelPolicy::overviewStages(2, 1, k, diag / 2, diag / 4, {}, {1, 2, 2});
  ASSERT_EQ(kept.size(), 3u);
  // medium from the zoom where a level-2 voxel (2 level-0 voxels) covers a pixel
  EXPECT_NEAR(kept[1].enterZoom, 1.0 / (2.0 * k), 1e-12);
  // native: where the view shows no more than the block, after medium
  const double medium = 1.0 / (2.0 * k);
  EXPECT_NEAR(kept[2].enterZoom, std::max({2.0, medium, medium * 1.001}), 1e-12);
  EXPECT_THROW(ZoomLevelPolicy::overviewStages(2, 1, k, diag / 2, diag / 4, {}, {1, 2}),
               InputError);
}

TEST(ZoomLevelPolicy, HysteresisKeepsTheStageNearAThreshold) {
  const ZoomLevelPolicy p(
      {{"coarse", 2, false, 0.0}, {"medium", 1, false, 1.0}, {"native", 0, true, 2.0}},
      {.hysteresis = 0.8});
  EXPECT_EQ(p.stageFor(0, 0.99), 0);
  EXPECT_EQ(p.stageFor(0, 1.0), 1);
  EXPECT_EQ(p.stageFor(1, 0.81), 1);  // inside the band: stays
  EXPECT_EQ(p.stageFor(1, 0.79), 0);
  EXPECT_EQ(p.stageFor(0, 2.5), 2);  // a large jump skips the medium stage
  EXPECT_EQ(p.stageFor(2, 1.7), 2);
  EXPECT_EQ(p.stageFor(2, 1.5), 1);
  EXPECT_EQ(p.stageFor(2, 0.5), 0);
  // A zoom jittering across the threshold swaps once, not every frame.
  ZoomLevelPolicy q(p.stages(), {.hysteresis = 0.8, .fadeMs = 0.0});
  q.update(0.5, 16.0);
  int swaps = 0, last = q.frame().stage;
  for (int i = 0; i < 100; ++i) {
    const ZoomFrame f = q.update(i % 2 ? 1.05 : 0.95, 16.0);
    swaps += f.stage != last ? 1 : 0;
    last = f.stage;
  }
  EXPECT_EQ(swaps, 1);
  EXPECT_THROW(ZoomLevelPolicy({{"a", 1, false, 1.0}, {"b", 0, false, 1.0}}), InputError);
}

TEST(ZoomLevelPolicy, CrossFadeHasNoJumpAndWaitsForResidentData) {
  ZoomLevelPolicy p({{"coarse", 2, false, 0.0}, {"medium", 1, false, 1.0}},
                    {.hysteresis = 0.8, .fadeMs = 100.0});
  std::vector<bool> resident = {true, false};
  ZoomFrame f = p.update(0.5, 0.0, &resident);
  EXPECT_EQ(f.stage, 0);
  // Zoomed in, but the medium level is still loading: the coarse stays whole.
  f = p.update(1.2, 16.0, &resident);
  EXPECT_TRUE(f.waiting);
  EXPECT_EQ(f.stage, 0);
  EXPECT_EQ(f.mix, 1.0);
  resident[1] = true;
  f = p.update(1.2, 16.0, &resident);
  EXPECT_EQ(f.stage, 1);
  EXPECT_EQ(f.from, 0);
  EXPECT_EQ(f.mix, 0.0);  // the first blended frame shows only the old image
  // The weight of the medium image, per frame of 20 ms: never a step larger
  // than 20 / 100 of the way.
  double weightMedium = 0.0;
  for (int i = 0; i < 3; ++i) {
    f = p.update(1.2, 20.0, &resident);
    const double w = f.stage == 1 ? f.mix : 1.0 - f.mix;
    EXPECT_NEAR(w - weightMedium, 0.2, 1e-12);
    weightMedium = w;
  }
  // Zooming back out mid-fade reverses it from where it is.
  f = p.update(0.5, 20.0, &resident);
  EXPECT_EQ(f.stage, 0);
  EXPECT_EQ(f.from, 1);
  const double wAfterReverse = 1.0 - f.mix;  // medium's weight
  EXPECT_NEAR(wAfterReverse, 0.8, 1e-12);    // advanced to 0.8, then reversed: continuous
  for (int i = 0; i < 10; ++i) f = p.update(0.5, 20.0, &resident);
  EXPECT_EQ(f.stage, 0);
  EXPECT_EQ(f.from, 0);
  EXPECT_EQ(f.mix, 1.0);
}
