// Pre-integrated classification (reference/PreIntegration.h) and the block
// walk of adaptive sampling (reference/AdaptiveSteps.h), on the CPU.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "support/TestCameras.h"
#include "support/TestTransferFunctions.h"
#include "tessera/core/Error.h"
#include "tessera/io/Procedural.h"
#include "tessera/reference/AdaptiveSteps.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/PreIntegration.h"
#include "tessera/reference/ReferenceRaycaster.h"

using namespace tessera;

namespace {

// The segment by brute force: a linear ramp from f to b over `length`,
// post-classified at 20000 steps.
glm::dvec4 bruteForceSegment(const TransferFunction& tf, double f, double b, double length) {
  const int n = 20000;
  const double ds = length / n;
  glm::dvec4 acc(0.0);
  for (int i = 0; i < n; ++i) {
    const double x = f + (b - f) * (i + 0.5) / n;
    const double a = tf.correctedOpacity(x, ds, 1.0);
    acc += (1.0 - acc.a) * glm::dvec4(tf.color(x) * a, a);
  }
  return acc;  // premultiplied
}

TransferFunction rampTf() {
  return test::tfFromPoints(
      {{0.0, {0.0, 0.0, 0.0}}, {0.5, {0.9, 0.5, 0.2}}, {1.0, {1.0, 1.0, 1.0}}},
      {{0.2, 0.0}, {0.6, 0.3}, {1.0, 0.6}});
}

}  // namespace

TEST(PreIntegration, EqualEndsGiveThePostClassifiedSample) {
  const TransferFunction tf = rampTf();
  const PreIntegral integral(tf, 0.7);
  for (double x : {0.0, 0.25, 0.5, 0.61, 1.0}) {
    for (double length : {0.25, 1.0, 3.0}) {
      const glm::dvec4 s = integral.segment(x, x, length);
      EXPECT_NEAR(s.a, tf.correctedOpacity(x, length, 0.7), 1e-9) << x;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(s[c], tf.color(x)[c], 1e-9) << x;
    }
  }
}

TEST(PreIntegration, OpacityIsExactForALinearRampAndColourClose) {
  const TransferFunction tf = rampTf();
  const PreIntegral integral(tf);
  for (auto [f, b, length] : {std::array<double, 3>{0.1, 0.9, 2.0},
                              {0.9, 0.1, 2.0},
                              {0.3, 0.35, 1.0},
                              {0.55, 0.75, 0.5},
                              {0.0, 1.0, 4.0}}) {
    const glm::dvec4 s = integral.segment(f, b, length);
    const glm::dvec4 brute = bruteForceSegment(tf, f, b, length);
    EXPECT_NEAR(s.a, brute.a, 1e-5) << f << ".." << b;
    double colour = 0.0;
    for (int c = 0; c < 3; ++c) colour = std::max(colour, std::abs(s[c] * s.a - brute[c]));
    // The colour neglects the order within the segment (PreIntegration.h):
    // a first-order error in the segment's opacity.
    std::printf(
        "  [measured] %.2f..%.2f over %.1f: opacity %.3f, premultiplied colour off by %.4f\n", f, b,
        length, s.a, colour);
    EXPECT_LT(colour, 0.1 * s.a) << f << ".." << b;
  }
}

TEST(PreIntegration, ALongerSegmentIsTheOpacityCorrectedShortOne) {
  const PreIntegral integral(rampTf());
  for (double m : {2.0, 4.0, 16.0}) {
    const glm::dvec4 one = integral.segment(0.3, 0.8, 0.5);
    const glm::dvec4 many = integral.segment(0.3, 0.8, 0.5 * m);
    EXPECT_NEAR(many.a, 1.0 - std::pow(1.0 - one.a, m), 1e-9);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(many[c], one[c], 1e-9);
  }
}

// Its build time is a benchmark figure (`tessera bench --sampling`), not a test.
TEST(PreIntegration, TableHoldsTheSegments) {
  const PreIntegral integral(rampTf());
  const std::vector<float> table = bakePreIntegrationTable(integral, 256, 0.5);
  ASSERT_EQ(table.size(), 256u * 256u * 4u);
  for (int j : {0, 17, 128, 255}) {
    for (int i : {0, 3, 128, 200, 255}) {
      const glm::dvec4 s = integral.segment(i / 255.0, j / 255.0, 0.5);
      for (int c = 0; c < 4; ++c) {
        EXPECT_NEAR(table[(static_cast<std::size_t>(j) * 256 + i) * 4 + c], s[c], 1e-6);
      }
    }
  }
  EXPECT_THROW(bakePreIntegrationTable(integral, 1, 0.5), InputError);
}

TEST(AdaptiveSteps, BlocksGetCodesFromTheTfOverTheirRange) {
  TransferFunction tf;
  tf.addColor(0.0, {1.0, 1.0, 1.0});
  tf.addOpacity(0.0, 0.0);
  tf.addOpacity(0.3, 0.0);  // 0..0.3: transparent
  tf.addOpacity(0.4, 0.5);  // steep
  tf.addOpacity(0.6, 0.5);  // 0.4..0.6 constant
  tf.addOpacity(1.0, 0.51);
  Sampling s;
  s.adaptive = true;
  s.tolerance = 0.2;
  s.maxMultiplier = 16;
  // Raw values 0..100 through the window 0..100.
  const std::vector<float> mins{0, 42, 25, 62};
  const std::vector<float> maxs{28, 58, 50, 100};
  const auto codes = classifyStepBlocks(mins, maxs, {0.0, 100.0}, tf, 1.0, 0.5, 256, s, true);
  const auto m = [&](const std::vector<std::uint8_t>& c, std::size_t b, double alpha = 0.0) {
    return stepMultiplier(c[b], alpha, s.maxMultiplier);
  };
  EXPECT_EQ(codes[0], 0) << "transparent over its range";
  EXPECT_EQ(m(codes, 1), 16) << "the TF is constant over its range";
  EXPECT_EQ(m(codes, 2), 1) << "the steep ramp";
  EXPECT_GT(m(codes, 3), 1);
  EXPECT_LT(m(codes, 3), 16) << "a gentle ramp";
  // Behind opacity the steps grow, by the transmittance: at 3/4 opacity 4x,
  // as far as the cap.
  EXPECT_EQ(m(codes, 3, 0.75), std::min(16.0, 4 * m(codes, 3)));
  // The steep ramp's base step is already over the tolerance (0.5 ds V > 0.2):
  // it grows only once (1 - A) brings it under.
  EXPECT_EQ(m(codes, 2, 0.5), 1);
  const auto fixed = classifyStepBlocks(mins, maxs, {0.0, 100.0}, tf, 1.0, 0.5, 256, s, false);
  EXPECT_EQ(fixed, (std::vector<std::uint8_t>{0, kUnitStepCode, kUnitStepCode, kUnitStepCode}));
  // A larger tolerance never takes smaller steps.
  s.tolerance = 1.0;
  const auto loose = classifyStepBlocks(mins, maxs, {0.0, 100.0}, tf, 1.0, 0.5, 256, s, true);
  for (std::size_t b = 0; b < codes.size(); ++b) EXPECT_GE(loose[b], codes[b]);
  s.maxMultiplier = 3;
  EXPECT_THROW(classifyStepBlocks(mins, maxs, {0.0, 100.0}, tf, 1.0, 0.5, 256, s, true),
               InputError);
}

TEST(AdaptiveSteps, WithoutABlockAheadTheWalkStaysOnTheLatticeAndCrossesFacesInOneStep) {
  for (double m : {2.0, 4.0, 8.0}) {
    for (double k = 0; k < 37; ++k) {
      const double kExit = 37;
      const double post = nextAdaptiveSample(k, m, kExit, {}, false);
      const double pre = nextAdaptiveSample(k, m, kExit, {}, true);
      EXPECT_GT(post, k);
      EXPECT_TRUE(std::fmod(post, m) == 0.0 || post == kExit) << k << " " << m;
      EXPECT_LE(post, kExit);
      EXPECT_GT(pre, k);
      EXPECT_TRUE(std::fmod(pre, m) == 0.0 || pre == kExit - 1 || pre == k + 1) << k;
      EXPECT_LE(pre, kExit);
      if (pre == kExit) {
        EXPECT_EQ(k, kExit - 1) << "a face is crossed by one base step";
      }
    }
  }
}

// With a visible block ahead a stretch or segment crosses the face on the
// lattice of the smaller multiplier and ends inside that block: it spans two
// blocks at most, each of which allows its length.
TEST(AdaptiveSteps, ABlockAheadLetsTheWalkCrossTheFaceWithTheSmallerMultiplier) {
  const double kExit = 37, kExitAhead = 53;
  for (double m : {1.0, 2.0, 4.0, 8.0, 16.0}) {
    for (double mAhead : {1.0, 2.0, 4.0, 8.0, 16.0}) {
      for (bool pre : {false, true}) {
        const double last = pre ? kExit - 1 : kExit;
        const double end = pre ? kExitAhead - 1 : kExitAhead;
        for (double k = 0; k < kExit; ++k) {
          const double next = nextAdaptiveSample(k, m, kExit, {mAhead, kExitAhead}, pre);
          EXPECT_GT(next, k);
          EXPECT_LE(next, end) << "ends inside the block ahead";
          if (nextMultiple(k, m) <= last) {
            EXPECT_EQ(next, nextMultiple(k, m)) << "inside the block: its own lattice";
          } else {  // toward the face: within what both blocks allow
            const double mc = std::min(m, mAhead);
            EXPECT_LE(next - k, mc) << k << " " << m << " " << mAhead;
            EXPECT_TRUE(std::fmod(next, mc) == 0.0 || next == end || next == k + 1)
                << k << " " << m << " " << mAhead;
          }
        }
        // The face costs no extra sample when the block ahead allows the
        // same multiplier: the walk keeps the lattice it had inside.
        const double k0 = std::floor((kExit - 1) / m) * m;
        if (m == mAhead && k0 + m <= end) {
          EXPECT_EQ(nextAdaptiveSample(k0, m, kExit, {m, kExitAhead}, pre), k0 + m)
              << m << " " << pre;
        }
      }
    }
  }
}

// Distance-based skipping: every empty block's distance is the chessboard
// distance to the nearest visible block, computed directly; a grid with no
// visible block is 255 everywhere.
TEST(AdaptiveSteps, EmptyDistanceIsTheChessboardDistanceToTheNearestVisibleBlock) {
  StepGrid grid;
  grid.count = {9, 6, 7};
  grid.codes.assign(9 * 6 * 7, 0);
  grid.measureEmptySpace();
  for (std::uint8_t d : grid.emptyDistance) EXPECT_EQ(d, 255);
  std::vector<glm::ivec3> visible = {{0, 0, 0}, {8, 5, 6}, {4, 2, 3}, {7, 0, 1}};
  for (glm::ivec3 v : visible) grid.codes[(v.z * 6 + v.y) * 9 + v.x] = 70;
  grid.measureEmptySpace();
  for (int z = 0; z < 7; ++z) {
    for (int y = 0; y < 6; ++y) {
      for (int x = 0; x < 9; ++x) {
        int direct = 1 << 20;
        for (glm::ivec3 v : visible) {
          direct =
              std::min(direct, std::max({std::abs(x - v.x), std::abs(y - v.y), std::abs(z - v.z)}));
        }
        EXPECT_EQ(grid.distance({x, y, z}), direct) << x << " " << y << " " << z;
      }
    }
  }
}

// The reference walking a grid of unit steps takes every sample: the same
// image as without a grid, post-classified and pre-integrated.
TEST(AdaptiveSteps, AGridOfUnitStepsIsTheUnwalkedReference) {
  const Volume v = makeSheppLogan({32, 32, 32});
  const TransferFunction tf = rampTf();
  Camera cam = test::orbitCamera(v.extent(), 30, 20);
  StepGrid grid;
  grid.dims = v.dims();
  grid.blockSize = 8;
  grid.count = glm::ivec3(4);
  grid.codes.assign(64, kUnitStepCode);
  for (bool pre : {false, true}) {
    RenderSettings s;
    s.sampling.preintegrate = pre;
    s.sampling.adaptive = true;
    s.sampling.opacityGrowth = false;
    const Image plain = renderReference(v, tf, cam, s, 48, 48);
    const Image walked = renderReference(v, tf, cam, s, 48, 48, 0, nullptr, nullptr, &grid);
    EXPECT_EQ(psnr(plain, walked), std::numeric_limits<double>::infinity()) << pre;
  }
}
