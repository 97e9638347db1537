// Bricks and levels without GL: the in-core and generated pyramids, stored
// bricks with their apron against direct indexing, level selection, and the
// streamer's cache, retries and failures.
#include <gtest/gtest.h>

#include "support/BricksTestSupport.h"

#include <cmath>

#include <algorithm>
#include <chrono>
#include <memory>
#include <set>
#include <unordered_map>
#include <vector>

#include "support/WrappedSources.h"
#include "tessera/core/Error.h"
#include "tessera/lod/BrickGrid.h"
#include "tessera/lod/BrickStreamer.h"
#include "tessera/lod/Downsample.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/lod/LevelSelection.h"
#include "tessera/lod/ProceduralMultiresSource.h"

using namespace tessera;

namespace {

std::shared_ptr<const Volume> hashVolume(glm::ivec3 dims) {
  auto v = std::make_shared<Volume>(Volume::allocate(dims, ScalarType::U8));
  for (std::size_t i = 0; i < v->voxelCount(); ++i) {
    v->setValueAtIndex(i, static_cast<double>((i * 2654435761u >> 7) % 251));
  }
  return v;
}

using test::FlakySource;

}  // namespace

TEST(BricksLod, InCorePyramidHalvesRoundingUpAndEqualsChainedDownsampling) {
  const auto v = hashVolume({37, 53, 29});
  const lod::InCoreMultiresSource src(v, 8);
  ASSERT_EQ(src.levelCount(), 4);  // 53 -> 27 -> 14 -> 7
  EXPECT_EQ(src.levelInfo(1).dims, glm::ivec3(19, 27, 15));
  EXPECT_EQ(src.levelInfo(3).dims, glm::ivec3(5, 7, 4));
  const Volume l1 = lod::downsample(*v, glm::ivec3(2));
  const Volume box = src.readBox(1, {{3, 4, 5}, {11, 20, 9}});
  ASSERT_EQ(box.dims(), glm::ivec3(8, 16, 4));
  for (int z = 0; z < 4; ++z)
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 8; ++x) ASSERT_EQ(box.valueAt(x, y, z), l1.valueAt(x + 3, y + 4, z + 5));
  EXPECT_THROW(src.readBox(0, {{0, 0, 0}, {38, 1, 1}}), Error);
}

TEST(BricksLod, StoredBrickIsTheBrickAndItsApronForEveryVoxel) {
  // B = 12 does not divide 37x53x29: partial bricks at the far faces.
  const auto v = hashVolume({37, 53, 29});
  auto src = std::make_shared<lod::InCoreMultiresSource>(v, 8);
  const lod::BrickGrid grid = lod::BrickGrid::of(*src, 12);
  EXPECT_EQ(grid.bricks(0), glm::ivec3(4, 5, 3));
  const lod::StoredMapping m = lod::StoredMapping::of(src->shape());
  for (int level = 0; level < grid.levelCount(); ++level) {
    const Volume& lv = src->level(level);
    const glm::ivec3 n = grid.bricks(level);
    for (int bz = 0; bz < n.z; ++bz)
      for (int by = 0; by < n.y; ++by)
        for (int bx = 0; bx < n.x; ++bx) {
          const lod::BrickKey key{level, {bx, by, bz}};
          const lod::StoredBrick b = lod::readStoredBrick(*src, grid, key, m);
          ASSERT_EQ(b.count(), 14u * 14u * 14u);
          std::size_t i = 0;
          int lo = 255, hi = 0;
          for (int z = 0; z < 14; ++z)
            for (int y = 0; y < 14; ++y)
              for (int x = 0; x < 14; ++x, ++i) {
                // Stored voxel (x,y,z) is level voxel brick*B - 1 + (x,y,z), clamped.
                const glm::ivec3 g = glm::clamp(key.brick * 12 - 1 + glm::ivec3(x, y, z),
                                                glm::ivec3(0), lv.dims() - 1);
                ASSERT_EQ(b.value(i), lv.valueAt(g.x, g.y, g.z)) << level << " " << i;
                lo = std::min<int>(lo, b.value(i));
                hi = std::max<int>(hi, b.value(i));
              }
          EXPECT_EQ(b.min, lo);
          EXPECT_EQ(b.max, hi);
        }
  }
}

TEST(BricksLod, LevelsGetCoarserWithDistanceAndTheCutStaysWithinCapacity) {
  const lod::BrickGrid grid(lod::pyramidDims({256, 256, 256}, 16), 16);
  lod::LodView view;
  view.eye = {128.0, 128.0, -40.0};  // in front of the z = 0 face
  view.pixelSize = 2.0 * std::tan(0.5 * 30.0 * 3.14159265 / 180.0) / 64.0;  // a 64-pixel view
  const auto all = [](const lod::BrickKey&) { return true; };
  const lod::LodSelection s = lod::selectBricks(grid, view, all, 100000);
  ASSERT_FALSE(s.bricks.empty());
  // The nearest brick is the finest, and levels never get finer with distance.
  EXPECT_EQ(s.bricks.front().level, 0);
  EXPECT_GT(s.bricks.back().level, 0);
  std::uint64_t covered = 0;
  for (const lod::BrickKey& k : s.bricks) {
    const glm::dvec3 e = grid.upperCorner(k) - grid.lowerCorner(k);
    covered += static_cast<std::uint64_t>(e.x * e.y * e.z);
  }
  EXPECT_EQ(covered, 256ull * 256 * 256) << "the cut covers the volume exactly once";
  const lod::LodSelection small = lod::selectBricks(grid, view, all, 40);
  EXPECT_LE(std::count_if(small.bricks.begin(), small.bricks.end(),
                          [&](const lod::BrickKey& k) { return k.level < grid.levelCount() - 1; }),
            40);
  EXPECT_TRUE(small.limitedByCapacity);
  // Transparent bricks are left out of the cut.
  const auto upperHalf = [](const lod::BrickKey& k) {
    return (k.brick.y + 1) * (16 << k.level) > 128;
  };
  for (const lod::BrickKey& k : lod::selectBricks(grid, view, upperHalf, 100000).bricks) {
    EXPECT_TRUE(upperHalf(k));
  }
}

TEST(BricksLod, StreamerRetriesFailingReadsWithBackOffAndKeepsTheCacheInBudget) {
  const auto v = hashVolume({64, 32, 32});
  auto inner = std::make_shared<lod::InCoreMultiresSource>(v, 8);
  auto flaky = std::make_shared<FlakySource>(inner, 16);
  const lod::BrickGrid grid = lod::BrickGrid::of(*flaky, 16);
  lod::BrickStreamerOptions o;
  o.cacheBytes = 3 * grid.storedVoxels();
  o.firstRetryMs = 1.0;
  o.maxRetryMs = 4.0;
  lod::BrickStreamer streamer(flaky, grid, o);
  std::vector<lod::BrickKey> keys;
  for (int x = 0; x < 4; ++x)
    for (int y = 0; y < 2; ++y)
      for (int z = 0; z < 2; ++z) keys.push_back({0, {x, y, z}});
  // Bounded by time, not by rounds: evicted good bricks are read again on
  // every request, so progress can wake hundreds of rounds within the few
  // milliseconds the failing bricks' back-off takes.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < deadline) {
    streamer.request(keys);
    streamer.waitForProgress(5.0);
    bool settled = true;
    for (const lod::BrickKey& k : keys) {
      settled =
          settled && (k.brick.x % 2 == 1 ? streamer.failing(k) : streamer.range(k).has_value());
    }
    if (settled) break;
  }
  for (const lod::BrickKey& k : keys) {
    if (k.brick.x % 2 == 1) {
      EXPECT_TRUE(streamer.failing(k));
      EXPECT_FALSE(streamer.range(k).has_value());
    } else {
      EXPECT_TRUE(streamer.range(k).has_value())
          << "good bricks are read despite failing neighbours";
    }
  }
  const lod::StreamerStats s = streamer.stats();
  EXPECT_GE(s.readErrors, 8u * 3);
  EXPECT_NE(s.lastError.find("unreachable"), std::string::npos) << s.lastError;
  EXPECT_LE(s.cachePeakBytes, o.cacheBytes);
  EXPECT_GE(s.bricksRead, 8u);  // evicted bricks are read again when asked for
  EXPECT_THROW(streamer.readNow({0, {1, 0, 0}}), Error);
}

TEST(BricksLod, GeneratedVolumeComputesAnyBoxConsistently) {
  const lod::ProceduralMultiresSource src("head:200x160x120");
  EXPECT_EQ(src.levelInfo(0).dims, glm::ivec3(200, 160, 120));
  EXPECT_EQ(src.levelCount(), 5);  // 200 100 50 25 13
  const Volume big = src.readBox(1, {{0, 0, 0}, {100, 80, 60}});
  const Volume part = src.readBox(1, {{31, 17, 40}, {45, 30, 60}});
  std::set<int> values;
  for (int z = 0; z < 20; ++z)
    for (int y = 0; y < 13; ++y)
      for (int x = 0; x < 14; ++x) {
        ASSERT_EQ(part.valueAt(x, y, z), big.valueAt(x + 31, y + 17, z + 40));
        values.insert(static_cast<int>(part.valueAt(x, y, z)));
      }
  EXPECT_GT(values.size(), 10u) << "a textured field, not a constant";
  // Level 1 point-samples the field at level-0 coordinate (2i + 1).
  EXPECT_EQ(big.valueAt(50, 40, 30), std::lround(src.valueAt({101.0, 81.0, 61.0})));
  EXPECT_THROW(lod::ProceduralMultiresSource("head:0"), InputError);
  EXPECT_THROW(lod::ProceduralMultiresSource("head:12x12"), InputError);
}

// head16: the same head in u16: the 8-bit field times 257 plus a texture
// finer than one 8-bit step, so 16-bit bricks have something to keep.
TEST(BricksLod, GeneratedSixteenBitHeadIsTheEightBitHeadWidened) {
  const lod::ProceduralMultiresSource u8("head:96x80x64"), u16("head16:96x80x64");
  EXPECT_EQ(u16.shape().type(), ScalarType::U16);
  EXPECT_EQ(u16.shape().valueRange().max, 65535.0);
  EXPECT_EQ(u16.levelCount(), u8.levelCount());
  const Volume a = u8.readBox(0, {{10, 20, 30}, {60, 50, 40}});
  const Volume b = u16.readBox(0, {{10, 20, 30}, {60, 50, 40}});
  ASSERT_EQ(b.type(), ScalarType::U16);
  std::size_t fine = 0;
  for (std::size_t i = 0; i < a.voxelCount(); ++i) {
    const double wide = b.valueAtIndex(i), narrow = a.valueAtIndex(i);
    ASSERT_GE(wide, narrow * 257.0 - 129.0) << i;
    ASSERT_LE(wide, narrow * 257.0 + 329.0) << i;  // < 0.5 rounding + 200 texture
    fine += narrow > 0 && std::fmod(wide, 257.0) != 0.0;
  }
  EXPECT_GT(fine, a.voxelCount() / 4) << "the low byte carries a texture";
  EXPECT_THROW(lod::ProceduralMultiresSource("head16:0"), InputError);
}

TEST(BricksLod, WithoutWorkerThreadsRequestReadsInline) {
  // The browser build has no threads: request() reads a few bricks itself.
  const auto v = hashVolume({48, 16, 16});
  auto src = std::make_shared<lod::InCoreMultiresSource>(v, 8);
  const lod::BrickGrid grid = lod::BrickGrid::of(*src, 16);
  lod::BrickStreamerOptions o;
  o.workers = 0;
  o.inlineReadsPerRequest = 2;
  lod::BrickStreamer streamer(src, grid, o);
  streamer.request({{0, {0, 0, 0}}, {0, {1, 0, 0}}, {0, {2, 0, 0}}});
  EXPECT_TRUE(streamer.find({0, {0, 0, 0}}));
  EXPECT_TRUE(streamer.find({0, {1, 0, 0}}));
  EXPECT_FALSE(streamer.find({0, {2, 0, 0}})) << "two per request";
  streamer.request({{0, {2, 0, 0}}});
  EXPECT_TRUE(streamer.find({0, {2, 0, 0}}));
  EXPECT_TRUE(streamer.idle());
}

namespace {

// A source whose bytes arrive asynchronously (the browser's fetch()): boxes
// starting in brick column 1 are not ready until `arrived`; it counts the
// prefetches that asked for them and any read of a box that was not ready.
class LateSource final : public test::WrappedSource {
 public:
  using WrappedSource::WrappedSource;
  Volume readBox(int level, const lod::VoxelBox& box) const override {
    if (!prefetch(level, box)) ++readsNotReady;
    return WrappedSource::readBox(level, box);
  }
  bool prefetch(int, const lod::VoxelBox& box) const override {
    if (column(box) != 1 || arrived) return true;
    ++asked;
    return false;
  }
  std::string describe() const override { return "late " + WrappedSource::describe(); }
  bool arrived = false;
  mutable int asked = 0;
  mutable int readsNotReady = 0;
};

}  // namespace

TEST(BricksLod, InlineStreamerSkipsBricksWhoseBytesHaveNotArrivedWithoutCountingFailures) {
  const auto v = hashVolume({48, 16, 16});
  auto late = std::make_shared<LateSource>(std::make_shared<lod::InCoreMultiresSource>(v, 8), 16);
  const lod::BrickGrid grid = lod::BrickGrid::of(*late, 16);
  lod::BrickStreamerOptions o;
  o.workers = 0;
  lod::BrickStreamer streamer(late, grid, o);
  const std::vector<lod::BrickKey> keys{{0, {0, 0, 0}}, {0, {1, 0, 0}}, {0, {2, 0, 0}}};
  streamer.request(keys);
  EXPECT_TRUE(streamer.find(keys[0]));
  EXPECT_FALSE(streamer.find(keys[1])) << "its bytes are on their way: not read, not waited for";
  EXPECT_TRUE(streamer.find(keys[2])) << "the brick behind it is read meanwhile";
  EXPECT_EQ(late->asked, 1);
  EXPECT_FALSE(streamer.failing(keys[1]));
  EXPECT_EQ(streamer.stats().readErrors, 0u);
  streamer.request(keys);
  EXPECT_EQ(late->asked, 2) << "asked for again on the next request";
  late->arrived = true;
  streamer.request(keys);
  EXPECT_TRUE(streamer.find(keys[1]));
  EXPECT_EQ(late->readsNotReady, 0);
  EXPECT_TRUE(streamer.idle());
}

// In a mean pyramid every brick's stored range lies within the bound each of
// its ancestors gives (the bricks layout leaves unread bricks out by it),
// also around lone bright voxels that the coarse levels average away.
TEST(BricksLod, MeanPyramidBoundHoldsForEveryBrickUnderEveryAncestor) {
  auto v = std::make_shared<Volume>(Volume::allocate({70, 45, 52}, ScalarType::U8));
  for (std::size_t i = 0; i < v->voxelCount(); ++i) {
    const std::size_t h = i * 2654435761u >> 9;
    v->setValueAtIndex(i, h % 997 == 0 ? 255.0 : h % 5 == 0 ? static_cast<double>(h % 7) : 0.0);
  }
  v->invalidateRange();
  const auto source = std::make_shared<lod::InCoreMultiresSource>(v, 8);
  ASSERT_TRUE(source->meanPyramid());
  const lod::BrickGrid grid = lod::BrickGrid::of(*source, 8);
  const lod::StoredMapping identity = lod::StoredMapping::of(source->shape());
  auto ranges = test::storedRanges(*source, grid, identity);
  int checked = 0, dimAncestorOfBright = 0;
  for (int l = 0; l + 1 < grid.levelCount(); ++l) {
    const glm::ivec3 n = grid.bricks(l);
    for (int z = 0; z < n.z; ++z)
      for (int y = 0; y < n.y; ++y)
        for (int x = 0; x < n.x; ++x) {
          const lod::BrickKey k{l, {x, y, z}};
          const lod::BrickRange r = ranges[l][k.id()];
          int up = 1;
          for (lod::BrickKey a = grid.parent(k); a.level < grid.levelCount();
               a = grid.parent(a), ++up) {
            const lod::BrickRange ar = ranges[a.level][a.id()];
            const lod::BrickRange bound = lod::meanPyramidBound(ar, up, 255);
            EXPECT_LE(bound.min, r.min) << "level " << l << " up " << up;
            EXPECT_GE(bound.max, r.max) << "level " << l << " up " << up;
            if (r.max == 255 && ar.max < 64) ++dimAncestorOfBright;
            ++checked;
          }
        }
  }
  EXPECT_GT(checked, 100);
  EXPECT_GT(dimAncestorOfBright, 0) << "the volume should hold bright voxels averaged away";
  // Over empty space the bound stays tight: a coarse maximum of 0.
  EXPECT_EQ(lod::meanPyramidBound({0, 0}, 1, 255).max, 8);
  EXPECT_EQ(lod::meanPyramidBound({0, 0}, 2, 255).max, 72);
}
