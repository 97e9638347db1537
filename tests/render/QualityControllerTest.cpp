// The interactive quality controller against a simulated renderer whose
// frame time is a fixed overhead plus a cost proportional to pixels x
// samples, with noise: the controller must settle at the goal from either
// side, degrade resolution before sample distance, and deliver one
// full-quality frame when the interaction ends.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

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

TEST(QualityController, RejectsBadOptions) {
  QualityController::Options o;
  o.goalMs = 0.0;
  EXPECT_THROW(QualityController{o}, tessera::InputError);
  o = {};
  o.minResolutionScale = 1.5;
  EXPECT_THROW(QualityController{o}, tessera::InputError);
}
