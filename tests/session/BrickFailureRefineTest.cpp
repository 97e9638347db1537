// Refining a view to completion (session::BrickRefinement::refine, what
// `tessera render` and the benchmarks run) when one brick's reads always
// fail, slowly, as a chunk whose storage retries first: the run ends within
// the streamer's failure policy, names the brick's source, and every other
// brick is resident at level 0 while the dead one shows level 1.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <memory>

#include "support/GpuTestContext.h"
#include "support/TestCameras.h"
#include "support/WrappedSources.h"
#include "tessera/gpu/DeviceSession.h"
#include "tessera/layout/BricksLayout.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/session/BrickRefinement.h"

using namespace tessera;

namespace {

constexpr int kImage = 128;

std::shared_ptr<const Volume> noise(int side) {
  auto v = std::make_shared<Volume>(Volume::allocate(glm::ivec3(side), ScalarType::U8));
  for (std::size_t i = 0; i < v->voxelCount(); ++i) {
    v->setValueAtIndex(i, static_cast<double>((i * 2654435761u >> 7) % 251));
  }
  v->invalidateRange();
  return v;
}

layout::BricksOptions bricksOf16() {
  layout::BricksOptions o;
  o.brickSize = 16;
  o.pixelsPerVoxel = 0.05;  // every brick wanted at level 0
  o.workers = 2;            // failures arrive from reader threads, as in use
  return o;
}

session::RefineRun refine(layout::BricksLayout& bricks, const Camera& cam,
                          const TransferFunction& tf) {
  return session::BrickRefinement(bricks).refine(cam, kImage, kImage, tf, [] {}, {});
}

}  // namespace

TEST(BrickFailureRefine, ADeadBrickEndsTheRunWithinThePolicyNamedAndAtItsCoarserLevel) {
  gpu::GlContext& c = test::gpuContext();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  const auto v = noise(64);
  const auto inner = std::make_shared<lod::InCoreMultiresSource>(v, 8);
  const Camera cam = test::orbitCamera(v->extent(), 30.0, 20.0);
  TransferFunction everything;  // every value visible: no transparent cells
  everything.addOpacity(0.0, 0.5);

  // What this machine takes to refine the view with every brick readable.
  auto healthy = layout::BricksLayout::create(inner, limits, c.ledger(), bricksOf16());
  const session::RefineRun h = refine(*healthy, cam, everything);
  ASSERT_TRUE(h.last.complete);
  ASSERT_EQ(h.last.wantedPerLevel[0], 64) << "the view wants all 4^3 level-0 bricks";
  EXPECT_TRUE(h.failedReads.empty());

  // Brick (1,1,1) fails after 250 ms, every time.
  constexpr double kFailMs = 250.0;
  const lod::BrickKey deadKey{0, {1, 1, 1}};
  auto dead = std::make_shared<test::DeadBricksSource>(inner, lod::BrickGrid::of(*inner, 16),
                                                       std::vector{deadKey}, kFailMs);
  auto bricks = layout::BricksLayout::create(dead, limits, c.ledger(), bricksOf16());
  const auto t0 = std::chrono::steady_clock::now();
  const session::RefineRun r = refine(*bricks, cam, everything);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  // The policy: attemptsBeforeFailing reads and the back-off before the
  // last two (20 + 40 ms); the other worker reads the rest meanwhile.
  const lod::BrickStreamerOptions policy;
  const double policyMs = policy.attemptsBeforeFailing * kFailMs + 3.0 * policy.firstRetryMs;
  const double bound = 3.0 * (h.completeMs + policyMs);
  std::printf(
      "  [measured] refined in %.0f ms with a dead brick (healthy %.0f ms, policy %.0f ms, "
      "bound %.0f ms), %d frames; %s\n",
      ms, h.completeMs, policyMs, bound, r.frames,
      r.failedReads.empty() ? "-" : r.failedReads[0].c_str());
  EXPECT_TRUE(r.last.complete);
  EXPECT_LE(ms, bound);
  EXPECT_EQ(dead->reads(0), policy.attemptsBeforeFailing);
  EXPECT_EQ(r.last.failing, 1);
  EXPECT_EQ(r.failedReads,
            std::vector<std::string>{"dead://store/0/1/1/1: HTTP 500 (test double)"});
  EXPECT_EQ(r.failedReadCount, 1u);

  // Every other cell at level 0, the dead one at level 1 (no hole).
  ASSERT_EQ(r.last.cellsPerLevel.size(),
            static_cast<std::size_t>(bricks->grid().levelCount()) + 1);  // + transparent
  EXPECT_EQ(r.last.cellsPerLevel[0], 63);
  EXPECT_EQ(r.last.cellsPerLevel[1], 1);
  for (int z = 0; z < 4; ++z)
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 4; ++x) {
        const glm::ivec3 cell(x, y, z);
        const int level = bricks->lookup((glm::dvec3(cell) + 0.5) * 16.0).level;
        EXPECT_EQ(level, cell == deadKey.brick ? 1 : 0) << x << "," << y << "," << z;
      }

  // Given up for the rest of the run: more frames do not read it again.
  session::BrickRefinement more(*bricks);
  for (int i = 0; i < 10; ++i) more.step(cam, kImage, kImage, everything, {0.0, 30.0});
  EXPECT_EQ(dead->reads(0), policy.attemptsBeforeFailing);
}
