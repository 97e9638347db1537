// The interactive quality controller against a simulated renderer whose
// frame time is a fixed overhead plus a cost proportional to pixels x
// samples, with noise: the controller must settle at the goal from either
// side, degrade resolution before sample distance, and deliver one
// full-quality frame when the interaction ends.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "tessera/core/Error.h"
#include "tessera/render/QualityController.h"

using tessera::render::QualityController;
using tessera::render::QualityLevel;

namespace {

struct SimulatedRenderer {
  double overheadMs;
  double fullMs;  // pixels x samples part at full quality
  std::mt19937 rng{7};
  double noise = 0.05;
  double frame(const QualityLevel& q) {
    std::normal_distribution<double> n(1.0, noise);
    return (overheadMs + fullMs * q.work()) * std::max(0.5, n(rng));
  }
};

}  // namespace

TEST(QualityController, SettlesAtTheGoalWhileInteracting) {
  for (double fullMs : {250.0, 2000.0}) {
    SimulatedRenderer r{4.0, fullMs};
    QualityController::Options o;
    o.goalMs = 40.0;
    QualityController qc(o);
    qc.setInteracting(true);
    double lastErr = 0.0;
    int within = 0;
    for (int f = 0; f < 30; ++f) {
      const QualityLevel q = qc.next();
      const double ms = r.frame(q);
      qc.report(q, ms);
      if (f >= 5) {
        within += std::abs(ms - o.goalMs) < 0.2 * o.goalMs;
        lastErr = std::abs(ms - o.goalMs) / o.goalMs;
      }
    }
    const QualityLevel settled = qc.next();
    std::printf(
        "  [measured] full frame %.0f ms, goal %.0f ms: %d/25 frames within 20 %%, "
        "settled at scale %.3f, step x%.2f (last error %.0f %%)\n",
        fullMs, o.goalMs, within, settled.resolutionScale, settled.stepScale, 100 * lastErr);
    EXPECT_GE(within, 20);
    // The settled work fraction predicts the goal under the model.
    const double predicted = 4.0 + fullMs * settled.work();
    EXPECT_NEAR(predicted, o.goalMs, 0.15 * o.goalMs);
  }
}

TEST(QualityController, ReducesResolutionBeforeSampleDistance) {
  QualityController::Options o;
  o.minResolutionScale = 0.25;
  o.maxStepScale = 4.0;
  QualityController qc(o);
  const QualityLevel mild = qc.levelFor(0.25);
  EXPECT_DOUBLE_EQ(mild.resolutionScale, 0.5);
  EXPECT_DOUBLE_EQ(mild.stepScale, 1.0);
  const QualityLevel hard = qc.levelFor(0.25 * 0.25 / 2.0);
  EXPECT_DOUBLE_EQ(hard.resolutionScale, 0.25);
  EXPECT_DOUBLE_EQ(hard.stepScale, 2.0);
  const QualityLevel floor = qc.levelFor(1e-9);  // clamped to the cheapest level
  EXPECT_DOUBLE_EQ(floor.resolutionScale, 0.25);
  EXPECT_DOUBLE_EQ(floor.stepScale, 4.0);
}

TEST(QualityController, DeliversOneFullQualityFrameWhenIdle) {
  SimulatedRenderer r{2.0, 500.0};
  QualityController qc;
  EXPECT_EQ(qc.state(), QualityController::State::Idle);
  qc.setInteracting(true);
  for (int f = 0; f < 10; ++f) {
    const QualityLevel q = qc.next();
    EXPECT_FALSE(q.full());
    qc.report(q, r.frame(q));
  }
  qc.setInteracting(false);
  EXPECT_EQ(qc.state(), QualityController::State::Idle);
  ASSERT_TRUE(qc.needsFrame());
  const QualityLevel idle = qc.next();
  EXPECT_TRUE(idle.full());
  const double idleMs = r.frame(idle);
  qc.report(idle, idleMs);
  EXPECT_FALSE(qc.needsFrame());
  // The idle frame's time seeds the next interaction close to the goal.
  qc.setInteracting(true);
  const QualityLevel first = qc.next();
  const double firstMs = 2.0 + 500.0 * first.work();
  std::printf("  [measured] idle frame %.0f ms; first interacting frame predicted %.0f ms\n",
              idleMs, firstMs);
  EXPECT_NEAR(firstMs, qc.options().goalMs, 0.3 * qc.options().goalMs);
}

// A frame due sooner than the goal (an input that has waited) takes the
// settled level's work shrunk in proportion: on a renderer that costs only
// its work it meets the time asked for; with a fixed cost it lands between
// that and the goal; the cheapest level when nothing is left; the settled
// level unchanged when the time is the goal or more.
TEST(QualityController, ShrinksTheWorkOfAFrameDueBeforeTheGoal) {
  for (double overheadMs : {0.0, 3.0}) {
    SimulatedRenderer r{overheadMs, 400.0};
    r.noise = 0.0;
    QualityController::Options o;
    o.goalMs = 12.0;
    o.minResolutionScale = 1.0 / 16.0;
    o.maxStepScale = 1.0;
    QualityController qc(o);
    qc.setInteracting(true);
    for (int f = 0; f < 40; ++f) {
      const QualityLevel q = qc.next();
      qc.report(q, r.frame(q));
    }
    const QualityLevel settled = qc.next();
    EXPECT_NEAR(r.frame(settled), o.goalMs, 0.05 * o.goalMs);
    for (double within : {9.0, 6.0}) {
      const QualityLevel q = qc.nextWithin(within);
      EXPECT_NEAR(q.work(), settled.work() * within / o.goalMs, 1e-12);
      EXPECT_DOUBLE_EQ(q.stepScale, 1.0);
      const double ms = r.frame(q);
      std::printf(
          "  [measured] overhead %.0f ms: a frame due in %.0f ms of a %.0f ms goal took %.2f ms\n",
          overheadMs, within, o.goalMs, ms);
      if (overheadMs == 0.0) {
        EXPECT_NEAR(ms, within, 1e-9);
      } else {
        EXPECT_GT(ms, within);
        EXPECT_LT(ms, r.frame(settled));
      }
    }
    const QualityLevel least = qc.nextWithin(-2.0);
    EXPECT_DOUBLE_EQ(least.resolutionScale, o.minResolutionScale);
    EXPECT_DOUBLE_EQ(least.stepScale, 1.0);
    EXPECT_DOUBLE_EQ(qc.nextWithin(o.goalMs).work(), settled.work());
    EXPECT_DOUBLE_EQ(qc.nextWithin(50.0).work(), settled.work());
  }
  // Idle: the full-quality frame, whatever is asked.
  QualityController idle;
  EXPECT_TRUE(idle.nextWithin(1.0).full());
}

// With a ladder, reduced resolutions are rungs minResolutionScale x
// 2^(k / steps), at most the continuous resolution and within one step of
// it; the full resolution stays full. Settling on a simulated renderer
// then uses few sizes, where the continuous controller uses a new one for
// nearly every frame.
TEST(QualityController, RoundsResolutionsDownToALadderOfRepeatingSizes) {
  QualityController::Options o;
  o.minResolutionScale = 1.0 / 16.0;
  o.maxStepScale = 1.0;
  QualityController continuous(o);
  o.resolutionStepsPerOctave = 4.0;
  QualityController ladder(o);
  for (double work = 1.0 / 256.0; work <= 1.0; work *= 1.07) {
    const double free = continuous.levelFor(work).resolutionScale;
    const double rung = ladder.levelFor(work).resolutionScale;
    const double k = 4.0 * std::log2(rung * 16.0);
    EXPECT_NEAR(k, std::round(k), 1e-9) << "work " << work;
    EXPECT_LE(rung, free + 1e-12);
    EXPECT_GT(rung, free * std::exp2(-0.25) - 1e-12);
  }
  EXPECT_DOUBLE_EQ(ladder.levelFor(1.0).resolutionScale, 1.0);
  EXPECT_DOUBLE_EQ(ladder.levelFor(1.0 / 256.0).resolutionScale, 1.0 / 16.0);
  // Preview sizes of a 256-pixel view while settling at the goal.
  auto sizes = [](QualityController qc) {
    SimulatedRenderer r{2.5, 800.0};
    r.noise = 0.3;
    qc.setInteracting(true);
    std::vector<int> seen;
    for (int f = 0; f < 60; ++f) {
      const QualityLevel q = qc.next();
      const int size = static_cast<int>(std::lround(256 * q.resolutionScale));
      if (std::find(seen.begin(), seen.end(), size) == seen.end()) seen.push_back(size);
      qc.report(q, r.frame(q));
    }
    return seen.size();
  };
  o.goalMs = 4.2;
  o.resolutionStepsPerOctave = 0.0;
  const std::size_t freeSizes = sizes(QualityController(o));
  o.resolutionStepsPerOctave = 4.0;
  const std::size_t ladderSizes = sizes(QualityController(o));
  std::printf("  [measured] 60 frames at a 4.2 ms goal: %zu sizes continuous, %zu on the ladder\n",
              freeSizes, ladderSizes);
  EXPECT_LE(ladderSizes, 4u);
  EXPECT_GE(freeSizes, 2 * ladderSizes);
  o.resolutionStepsPerOctave = -1.0;
  EXPECT_THROW(QualityController{o}, tessera::InputError);
}

TEST(QualityController, RejectsBadOptions) {
  QualityController::Options o;
  o.goalMs = 0.0;
  EXPECT_THROW(QualityController{o}, tessera::InputError);
  o = {};
  o.minResolutionScale = 1.5;
  EXPECT_THROW(QualityController{o}, tessera::InputError);
}
