// The exact FCC box spline evaluator against an independent slow evaluation
// of the definition, and the properties the theory predicts.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <tuple>

#include <glm/geometric.hpp>

#include "lattice/SlowBoxSpline.h"
#include "tessera/lattice/FccBoxSpline.h"

using namespace tessera::lattice;
namespace slow = tessera::lattice::test;

namespace {

// Deterministic pseudo-random coefficients in [-1, 1] for any lattice point.
double hashedCoefficient(glm::ivec3 p) {
  std::uint32_t h = static_cast<std::uint32_t>(p.x * 73856093) ^
                    static_cast<std::uint32_t>(p.y * 19349663) ^
                    static_cast<std::uint32_t>(p.z * 83492791);
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return (h & 0xffff) / 32767.5 - 1.0;
}

// s(u) and its gradient for coefficients given by a function of the point.
template <class F>
BoxSplineSample splineOf(glm::dvec3 u, F c) {
  const BoxSplineStencil s = locateBoxSpline(u);
  std::array<double, kBoxSplineStencilSize> coeffs;
  for (std::size_t k = 0; k < coeffs.size(); ++k) coeffs[k] = c(s.points[k]);
  return evaluateBoxSpline(s, coeffs);
}

glm::dvec3 randomPoint(std::mt19937& rng, double lo, double hi) {
  std::uniform_real_distribution<double> d(lo, hi);
  return {d(rng), d(rng), d(rng)};
}

double maxAbs(glm::dvec3 v) {
  return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
}

}  // namespace

TEST(FccBoxSpline, KernelMatchesSlowConvolutionOfTheDefinition) {
  std::mt19937 rng(1);
  double worstValue = 0.0, worstGradient = 0.0;
  std::vector<glm::dvec3> xs;
  for (int i = 0; i < 2000; ++i) xs.push_back(randomPoint(rng, -2.2, 2.2));
  // Points on knot planes and lattice points, where pieces meet.
  for (int i = -2; i <= 2; ++i) {
    for (int j = -2; j <= 2; ++j) {
      xs.push_back({i, j, 0.3});
      xs.push_back({i + 0.5, j, 1.0 - i - 0.5 - j});  // on x + y + z = 1
      for (int k = -2; k <= 2; ++k) xs.push_back({i, j, k});
    }
  }
  for (const glm::dvec3 x : xs) {
    const BoxSplineSample fast = boxSplineKernel(x);
    worstValue = std::max(worstValue, std::abs(fast.value - slow::slowKernel(x)));
    worstGradient = std::max(worstGradient, maxAbs(fast.gradient - slow::slowKernelGradient(x)));
  }
  std::printf("[measured] kernel vs slow convolution at %zu points: value %.2e, gradient %.2e\n",
              xs.size(), worstValue, worstGradient);
  EXPECT_LT(worstValue, 1e-9);
  EXPECT_LT(worstGradient, 1e-9);
}

TEST(FccBoxSpline, SplineMatchesSlowSumOverEveryLatticePoint) {
  std::mt19937 rng(2);
  double worstValue = 0.0, worstGradient = 0.0;
  for (int i = 0; i < 300; ++i) {
    const glm::dvec3 u = randomPoint(rng, -3.0, 3.0);
    const BoxSplineSample fast = splineOf(u, hashedCoefficient);
    worstValue =
        std::max(worstValue, std::abs(fast.value - slow::slowSpline(u, hashedCoefficient)));
    worstGradient = std::max(
        worstGradient, maxAbs(fast.gradient - slow::slowSplineGradient(u, hashedCoefficient)));
  }
  std::printf("[measured] spline vs slow sum over all lattice points: value %.2e, gradient %.2e\n",
              worstValue, worstGradient);
  EXPECT_LT(worstValue, 1e-9);
  EXPECT_LT(worstGradient, 1e-9);
}

TEST(FccBoxSpline, SlowEvaluationIsTheNormalisedBoxSpline) {
  // The reference itself: K(0) = 1/2 and the 12 nearest neighbours share the
  // rest (both from the definition, independent of the pieces).
  EXPECT_NEAR(slow::slowKernel(glm::dvec3(0.0)), 0.5, 1e-14);
  EXPECT_NEAR(slow::slowKernel({1, 1, 0}), 1.0 / 24.0, 1e-14);
  EXPECT_NEAR(slow::slowKernel({2, 0, 0}), 0.0, 1e-14);
  std::mt19937 rng(3);
  for (int i = 0; i < 20; ++i) {
    const glm::dvec3 u = randomPoint(rng, -1.0, 1.0);
    EXPECT_NEAR(slow::slowSpline(u, [](glm::ivec3) { return 1.0; }), 1.0, 1e-13);
  }
}

TEST(FccBoxSpline, ShiftsOnTheLatticeArePartitionOfUnity) {
  std::mt19937 rng(4);
  double worst = 0.0;
  for (int i = 0; i < 20000; ++i) {
    const glm::dvec3 u = randomPoint(rng, -50.0, 50.0);
    const BoxSplineSample s = splineOf(u, [](glm::ivec3) { return 1.0; });
    worst = std::max({worst, std::abs(s.value - 1.0), maxAbs(s.gradient)});
  }
  EXPECT_LT(worst, 1e-13);
}

TEST(FccBoxSpline, KernelHasTheSymmetryOfTheCube) {
  // All 48 signed permutations of the axes map the six directions (up to
  // sign) onto themselves, so K must not change.
  std::mt19937 rng(5);
  const std::array<std::array<int, 3>, 6> perms = {
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  double worst = 0.0;
  for (int i = 0; i < 300; ++i) {
    const glm::dvec3 x = randomPoint(rng, -2.1, 2.1);
    const double k = boxSplineKernel(x).value;
    for (const auto& p : perms) {
      for (int signs = 0; signs < 8; ++signs) {
        glm::dvec3 y;
        for (int a = 0; a < 3; ++a) y[a] = ((signs >> a) & 1 ? -1.0 : 1.0) * x[p[a]];
        worst = std::max(worst, std::abs(boxSplineKernel(y).value - k));
      }
    }
  }
  EXPECT_LT(worst, 1e-14);
}

TEST(FccBoxSpline, SupportIsTheTruncatedOctahedronAndSixteenPointsCoverEverySample) {
  std::mt19937 rng(6);
  for (int i = 0; i < 5000; ++i) {
    const glm::dvec3 x = randomPoint(rng, -2.5, 2.5);
    const double inf = maxAbs(x), one = std::abs(x.x) + std::abs(x.y) + std::abs(x.z);
    const double k = boxSplineKernel(x).value;
    if (inf >= 2.0 || one >= 3.0) {
      EXPECT_EQ(k, 0.0) << x.x << " " << x.y << " " << x.z;
    } else if (inf < 1.99 && one < 2.99) {
      EXPECT_GT(k, 0.0) << x.x << " " << x.y << " " << x.z;
    }
  }
  // The stencil is exactly the set of lattice points whose shifted kernel is
  // not zero at u (found by brute force with the slow evaluation).
  for (int i = 0; i < 200; ++i) {
    const glm::dvec3 u = randomPoint(rng, -4.0, 4.0);
    std::set<std::tuple<int, int, int>> brute, stencil;
    const glm::ivec3 o(glm::floor(u));
    for (int z = o.z - 3; z <= o.z + 4; ++z) {
      for (int y = o.y - 3; y <= o.y + 4; ++y) {
        for (int x = o.x - 3; x <= o.x + 4; ++x) {
          if (((x + y + z) & 1) == 0 && slow::slowKernel(u - glm::dvec3(x, y, z)) > 1e-15) {
            brute.insert({x, y, z});
          }
        }
      }
    }
    for (const glm::ivec3 p : locateBoxSpline(u).points) stencil.insert({p.x, p.y, p.z});
    EXPECT_EQ(stencil.size(), 16u);
    EXPECT_EQ(brute, stencil);
  }
}

// Samples of a polynomial p on the lattice: linear p comes back exactly,
// a quadratic as p + laplacian(p) / 6 (second moment I/3 per axis), and
// coefficients p - laplacian(p) / 6 reproduce it exactly. A cubic is not
// reproduced: the spline space holds exactly the quadratics.
TEST(FccBoxSpline, ReproducesLinearAndQuadraticPolynomials) {
  std::mt19937 rng(7);
  auto linear = [](glm::dvec3 p) { return 0.7 * p.x - 1.3 * p.y + 0.4 * p.z + 2.0; };
  auto quadratic = [](glm::dvec3 p) {
    return 0.3 * p.x * p.x - 0.8 * p.y * p.y + 0.2 * p.z * p.z + 0.5 * p.x * p.y - 0.9 * p.y * p.z +
           0.6 * p.x * p.z + p.x - 2.0;
  };
  const double laplacian = 2.0 * (0.3 - 0.8 + 0.2);
  auto cubic = [](glm::dvec3 p) { return p.x * p.y * p.z + 0.5 * p.x * p.x * p.x; };
  double worstLinear = 0.0, worstQuadratic = 0.0, worstQuasi = 0.0, cubicDeviation = 0.0;
  for (int i = 0; i < 2000; ++i) {
    const glm::dvec3 u = randomPoint(rng, -5.0, 5.0);
    auto at = [](auto f) { return [f](glm::ivec3 j) { return f(glm::dvec3(j)); }; };
    worstLinear = std::max(worstLinear, std::abs(splineOf(u, at(linear)).value - linear(u)));
    worstQuadratic = std::max(
        worstQuadratic, std::abs(splineOf(u, at(quadratic)).value - quadratic(u) - laplacian / 6));
    const double quasi =
        splineOf(u, [&](glm::ivec3 j) { return quadratic(glm::dvec3(j)) - laplacian / 6; }).value;
    worstQuasi = std::max(worstQuasi, std::abs(quasi - quadratic(u)));
    // cubic: laplacian = 3 x; its smoothed image would be cubic + x / 2.
    cubicDeviation =
        std::max(cubicDeviation, std::abs(splineOf(u, at(cubic)).value - cubic(u) - 0.5 * u.x));
  }
  std::printf(
      "[measured] reproduction error: linear %.1e, quadratic %.1e (quasi-interpolated "
      "%.1e), cubic deviates by %.3f\n",
      worstLinear, worstQuadratic, worstQuasi, cubicDeviation);
  EXPECT_LT(worstLinear, 1e-12);
  EXPECT_LT(worstQuadratic, 1e-11);
  EXPECT_LT(worstQuasi, 1e-11);
  EXPECT_GT(cubicDeviation, 1e-3);
}

// Across every knot plane the value and gradient are continuous (C1); the
// second derivative jumps across the x +- y +- z planes, which contain three
// of the six directions (smoothness #(directions off the plane) - 2 = 1), and
// not across the axis planes (two directions in them: C2 there).
TEST(FccBoxSpline, IsC1EverywhereAndOnlyC1AcrossTheDiagonalKnotPlanes) {
  struct Family {
    const char* name;
    glm::dvec3 normal;
    bool oddOffset;  // plane n . u = odd integer (else any integer)
  };
  const std::array<Family, 5> families = {{{"x = k", {1, 0, 0}, false},
                                           {"x+y+z = odd", {1, 1, 1}, true},
                                           {"x+y-z = odd", {1, 1, -1}, true},
                                           {"x-y+z = odd", {1, -1, 1}, true},
                                           {"-x+y+z = odd", {-1, 1, 1}, true}}};
  std::mt19937 rng(8);
  constexpr double kEps = 1e-7, kStep = 1e-3;
  for (const Family& f : families) {
    const glm::dvec3 n = glm::normalize(f.normal);
    double valueJump = 0.0, gradientJump = 0.0, secondJump = 0.0;
    for (int i = 0; i < 400; ++i) {
      glm::dvec3 u = randomPoint(rng, -4.0, 4.0);
      // Project onto the nearest plane of the family.
      const double s = glm::dot(f.normal, u);
      const double target = f.oddOffset ? 2.0 * std::floor(s / 2.0) + 1.0 : std::round(s);
      u += (target - s) / glm::dot(f.normal, f.normal) * f.normal;
      auto side = [&](double sign) { return splineOf(u + sign * kEps * n, hashedCoefficient); };
      const BoxSplineSample a = side(-1.0), b = side(1.0);
      valueJump = std::max(valueJump, std::abs(a.value - b.value));
      gradientJump = std::max(gradientJump, maxAbs(a.gradient - b.gradient));
      // Normal second derivative from each side, one-sided differences.
      auto dn = [&](double t) {
        return glm::dot(splineOf(u + t * n, hashedCoefficient).gradient, n);
      };
      const double before = (dn(-kEps) - dn(-kStep)) / (kStep - kEps);
      const double after = (dn(kStep) - dn(kEps)) / (kStep - kEps);
      secondJump = std::max(secondJump, std::abs(after - before));
    }
    std::printf(
        "[measured] across %-13s value jump %.1e, gradient jump %.1e, 2nd derivative "
        "jump %.2e\n",
        f.name, valueJump, gradientJump, secondJump);
    EXPECT_LT(valueJump, 1e-6);
    EXPECT_LT(gradientJump, 1e-5);
    if (f.oddOffset) {
      EXPECT_GT(secondJump, 1e-2);
    } else {
      EXPECT_LT(secondJump, 1e-2);
    }
  }
}
