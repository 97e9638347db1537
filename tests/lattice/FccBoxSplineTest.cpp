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
