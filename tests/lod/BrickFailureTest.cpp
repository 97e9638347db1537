// The streamer's failure policy, without GL: bricks whose reads keep failing
// (slowly, as a chunk whose storage retries first does) neither starve the
// bricks behind them nor hold a refinement up: given up, each is read
// attemptsBeforeFailing times and listed once by the URL it names; the
// viewers' default keeps retrying them.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <vector>

#include "support/WrappedSources.h"
#include "tessera/lod/BrickGrid.h"
#include "tessera/lod/BrickStreamer.h"
#include "tessera/lod/InCoreMultiresSource.h"

using namespace tessera;

namespace {

using test::DeadBricksSource;

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// 64x32x32 voxels in 16^3 bricks: 4x2x2 bricks at level 0. The dead ones are
// column 0 (the nearest to an eye at -x, so first in every request).
struct Bricks {
  std::shared_ptr<const lod::MultiresSource> inner;
  lod::BrickGrid grid;
  std::vector<lod::BrickKey> dead, good, all;
};

Bricks bricks(int deadCount) {
  auto v = std::make_shared<Volume>(Volume::allocate({64, 32, 32}, ScalarType::U8));
  for (std::size_t i = 0; i < v->voxelCount(); ++i) {
    v->setValueAtIndex(i, static_cast<double>((i * 2654435761u >> 7) % 251));
  }
  Bricks b{std::make_shared<lod::InCoreMultiresSource>(v, 8), {}, {}, {}, {}};
  b.grid = lod::BrickGrid::of(*b.inner, 16);
  for (int x = 0; x < 4; ++x)
    for (int z = 0; z < 2; ++z)
      for (int y = 0; y < 2; ++y) {
        const lod::BrickKey k{0, {x, y, z}};
        (static_cast<int>(b.dead.size()) < deadCount ? b.dead : b.good).push_back(k);
      }
  b.all = b.dead;
  b.all.insert(b.all.end(), b.good.begin(), b.good.end());
  return b;
}

// Requests `keys` every few ms (a frame loop) until `done` or `seconds`.
template <class Done>
double requestUntil(lod::BrickStreamer& s, const std::vector<lod::BrickKey>& keys, Done done,
                    double seconds) {
  const auto t0 = std::chrono::steady_clock::now();
  while (!done() && msSince(t0) < 1000.0 * seconds) {
    s.request(keys);
    s.waitForProgress(5.0);
  }
  return msSince(t0);
}

}  // namespace

// Four bricks fail after 200 ms each, with a back-off (50 ms at most) shorter
// than the two workers take to fail them all: asked for first every frame,
// they once kept both workers busy and the twelve good bricks were never
// read. Now the good ones come within one round of the dead ones.
TEST(BrickFailure, SlowFailingBricksDoNotStarveTheOthersAndViewersKeepRetrying) {
  const Bricks b = bricks(4);
  constexpr double kFailMs = 200.0;
  auto dead = std::make_shared<DeadBricksSource>(b.inner, b.grid, b.dead, kFailMs);
  lod::BrickStreamerOptions o;
  o.workers = 2;
  o.maxRetryMs = 50.0;
  lod::BrickStreamer s(dead, b.grid, o);
  auto goodRead = [&] {
    for (const lod::BrickKey& k : b.good)
      if (!s.range(k)) return false;
    return true;
  };
  const double ms = requestUntil(s, b.all, goodRead, 10.0);
  // One round of the dead bricks (4 x 200 ms over 2 workers), then the rest.
  const double bound = 3.0 * (b.dead.size() * kFailMs / o.workers + 100.0);
  std::printf("  [measured] 12 good bricks read after %.0f ms beside 4 failing ones (bound %.0f)\n",
              ms, bound);
  ASSERT_TRUE(goodRead()) << "starved for " << ms << " ms";
  EXPECT_LE(ms, bound);
  // The default (a viewer): failing bricks are still read after their
  // back-off, past attemptsBeforeFailing.
  auto retried = [&] {
    for (std::size_t i = 0; i < b.dead.size(); ++i)
      if (dead->reads(i) <= o.attemptsBeforeFailing) return false;
    return true;
  };
  requestUntil(s, b.all, retried, 10.0);
  for (std::size_t i = 0; i < b.dead.size(); ++i) {
    EXPECT_TRUE(s.failing(b.dead[i]));
    EXPECT_GT(dead->reads(i), o.attemptsBeforeFailing) << "brick " << i << " no longer retried";
  }
}

// Given up (a refine-to-completion run): each dead brick is read exactly
// attemptsBeforeFailing times within the policy's time, never again, and
// its error (naming its URL) is listed once; nothing is left in flight.
TEST(BrickFailure, GivenUpBricksAreReadAttemptsTimesWithinThePolicyAndListed) {
  const Bricks b = bricks(4);
  constexpr double kFailMs = 100.0;
  auto dead = std::make_shared<DeadBricksSource>(b.inner, b.grid, b.dead, kFailMs);
  lod::BrickStreamerOptions o;
  o.workers = 2;
  lod::BrickStreamer s(dead, b.grid, o);
  s.retryFailing(false);
  auto settled = [&] {
    for (const lod::BrickKey& k : b.dead)
      if (!s.failing(k)) return false;
    for (const lod::BrickKey& k : b.good)
      if (!s.range(k)) return false;
    return true;
  };
  const double ms = requestUntil(s, b.all, settled, 20.0);
  // The policy: attemptsBeforeFailing reads of every dead brick shared by the
  // workers, and the back-off before the last two reads (20 + 40 ms).
  const double policy = b.dead.size() * o.attemptsBeforeFailing * kFailMs / o.workers +
                        o.firstRetryMs + 2.0 * o.firstRetryMs;
  std::printf("  [measured] 4 bricks given up after %.0f ms (policy %.0f ms, bound x3 + 100)\n", ms,
              policy);
  ASSERT_TRUE(settled());
  EXPECT_LE(ms, 3.0 * (policy + 100.0));
  // Asked for again for longer than any back-off: not read again.
  requestUntil(
      s, b.all, [] { return false; }, 0.3);
  EXPECT_TRUE(s.idle()) << "a given-up brick is being read";
  std::vector<std::string> expected;
  for (std::size_t i = 0; i < b.dead.size(); ++i) {
    EXPECT_EQ(dead->reads(i), o.attemptsBeforeFailing) << "brick " << i;
    expected.push_back(DeadBricksSource::url(b.dead[i]) + ": HTTP 500 (test double)");
  }
  std::sort(expected.begin(), expected.end());
  const lod::StreamerStats st = s.stats();
  EXPECT_EQ(st.failingBricks, b.dead.size());
  EXPECT_EQ(st.failingErrors, expected);
  EXPECT_EQ(st.failingErrorCount, b.dead.size());
  EXPECT_EQ(st.readErrors, b.dead.size() * o.attemptsBeforeFailing);
}

// Ten failing bricks: under one chunk (one URL) they are listed once; with
// ten URLs the list stops at kListedErrors and counts the rest.
TEST(BrickFailure, FailingErrorsAreDistinctAndCapped) {
  const Bricks b = bricks(10);
  for (const bool oneChunk : {true, false}) {
    SCOPED_TRACE(oneChunk ? "one chunk" : "ten chunks");
    auto dead = std::make_shared<DeadBricksSource>(b.inner, b.grid, b.dead, 0.0,
                                                   oneChunk ? "http://h/s.zarr/0/0/0/0" : "");
    lod::BrickStreamerOptions o;
    o.workers = 2;
    lod::BrickStreamer s(dead, b.grid, o);
    s.retryFailing(false);
    requestUntil(
        s, b.all, [&] { return s.stats().failingBricks == b.dead.size() && s.idle(); }, 10.0);
    const lod::StreamerStats st = s.stats();
    EXPECT_EQ(st.failingBricks, 10u);
    if (oneChunk) {
      EXPECT_EQ(st.failingErrorCount, 1u);
      EXPECT_EQ(st.failingErrors,
                std::vector<std::string>{"http://h/s.zarr/0/0/0/0: HTTP 500 (test double)"});
    } else {
      EXPECT_EQ(st.failingErrorCount, 10u);
      EXPECT_EQ(st.failingErrors.size(), lod::StreamerStats::kListedErrors);
    }
  }
}
