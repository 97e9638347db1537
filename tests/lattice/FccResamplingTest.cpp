// Putting data on the lattice: the Cartesian interpolants, resampling,
// direct sampling and the quasi-interpolation prefilter.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "lattice/CartesianInterpolant.h"
#include "tessera/core/Error.h"
#include "tessera/lattice/FccBoxSpline.h"
#include "tessera/lattice/FccResampling.h"

using namespace tessera;
using namespace tessera::lattice;

namespace {

Volume randomU8(glm::ivec3 dims, unsigned seed) {
  Volume v = Volume::allocate(dims, ScalarType::U8, "random");
  std::mt19937 rng(seed);
  for (std::size_t i = 0; i < v.voxelCount(); ++i) v.setValueAtIndex(i, rng() % 256);
  return v;
}

Volume sampled(glm::ivec3 dims, double (*f)(glm::dvec3)) {
  Volume v = Volume::allocate(dims, ScalarType::F32, "function");
  for (int z = 0; z < dims.z; ++z) {
    for (int y = 0; y < dims.y; ++y) {
      for (int x = 0; x < dims.x; ++x) v.setValueAtIndex(v.index(x, y, z), f({x, y, z}));
    }
  }
  return v;
}

double smoothWave(glm::dvec3 x) {
  return std::sin(0.45 * x.x + 0.2) * std::cos(0.3 * x.y - 0.1) + 0.5 * std::sin(0.25 * x.z);
}

}  // namespace

TEST(CartesianInterpolant, MirrorIndexReflectsAboutBothEnds) {
  EXPECT_EQ(detail::mirrorIndex(-1, 5), 1);
  EXPECT_EQ(detail::mirrorIndex(-4, 5), 4);
  EXPECT_EQ(detail::mirrorIndex(5, 5), 3);
  EXPECT_EQ(detail::mirrorIndex(9, 5), 1);
  EXPECT_EQ(detail::mirrorIndex(3, 2), 1);
  EXPECT_EQ(detail::mirrorIndex(-7, 1), 0);
}

// After the prefilter, (c_{k-1} + 4 c_k + c_{k+1}) / 6 gives back every
// sample, the mirrored ends included.
TEST(CartesianInterpolant, BSplinePrefilterInterpolatesEveryLineLength) {
  std::mt19937 rng(9);
  for (const int n : {2, 3, 4, 7, 40}) {
    std::vector<double> f(static_cast<std::size_t>(n));
    for (double& v : f) v = std::uniform_real_distribution<double>(-1, 1)(rng);
    std::vector<double> c = f;
    detail::cubicBSplinePrefilter(c);
    for (int k = 0; k < n; ++k) {
      auto at = [&](int i) { return c[static_cast<std::size_t>(detail::mirrorIndex(i, n))]; };
      EXPECT_NEAR((at(k - 1) + 4 * at(k) + at(k + 1)) / 6.0, f[static_cast<std::size_t>(k)], 1e-12)
          << n << " " << k;
    }
  }
}

TEST(CartesianInterpolant, InterpolatingKernelsReturnTheVoxelsAtTheirCentres) {
  const Volume v = sampled({9, 8, 7}, smoothWave);
  for (const auto kind : {CartesianInterpolant::CubicBSpline, CartesianInterpolant::CatmullRom,
                          CartesianInterpolant::Trilinear}) {
    const detail::CartesianInterpolantField field(v, kind);
    for (int z = 0; z < 7; ++z) {
      for (int y = 0; y < 8; ++y) {
        for (int x = 0; x < 9; ++x) {
          EXPECT_NEAR(field.at({x, y, z}), v.valueAt(x, y, z), 2e-6) << static_cast<int>(kind);
        }
      }
    }
  }
}

// At half density the lattice points are the source's voxel centres: every
// interpolant hands over the voxels themselves.
TEST(FccResampling, HalfDensityKeepsTheSourceVoxelsExactly) {
  const Volume source = randomU8({11, 8, 9}, 10);
  for (const auto kind : {CartesianInterpolant::CubicBSpline, CartesianInterpolant::CatmullRom,
                          CartesianInterpolant::Trilinear}) {
    FccResampleOptions options;
    options.density = FccDensity::Half;
    options.interpolant = kind;
    options.quasiInterpolate = false;
    const FccVolume fcc = resampleToFcc(source, options);
    EXPECT_EQ(fcc.packed().type(), ScalarType::U8);
    EXPECT_EQ(fcc.gridDims(), source.dims());
    for (int z = 0; z < 9; ++z) {
      for (int y = 0; y < 8; ++y) {
        for (int x = (y + z) & 1; x < 11; x += 2) {
          ASSERT_EQ(fcc.value({x, y, z}), source.valueAt(x, y, z)) << x << " " << y << " " << z;
        }
      }
    }
  }
}

TEST(FccResampling, ThreadCountDoesNotChangeTheResult) {
  const Volume source = sampled({40, 36, 33}, smoothWave);
  FccResampleOptions one, many;
  one.threads = 1;
  many.threads = 4;
  const FccVolume a = resampleToFcc(source, one), b = resampleToFcc(source, many);
  ASSERT_EQ(a.byteSize(), b.byteSize());
  EXPECT_EQ(std::memcmp(a.packed().bytes().data(), b.packed().bytes().data(), a.byteSize()), 0);
  EXPECT_TRUE(a.quasiInterpolated());
}

// Quasi-interpolated samples of a quadratic give the quadratic back (f32
// texels: to float precision), away from the boundary rule's reach.
TEST(FccResampling, QuasiInterpolationReproducesQuadraticsThroughTheLattice) {
  Volume box = Volume::shapeOnly({20, 20, 20}, ScalarType::F32);
  box.setWindow({0.0, 1.0});
  auto q = [](glm::dvec3 u) {
    return 0.01 * (u.x * u.x - 2.0 * u.y * u.z + 0.5 * u.z * u.z) + 0.1 * u.y;
  };
  // Lattice half density = grid of the box: grid coordinate u = p * 20 - 0.5.
  const FccVolume fcc =
      sampleOnFcc(box, FccDensity::Half, [&](glm::dvec3 p) { return q(p * 20.0 - 0.5); });
  const FccBoxSpline spline(fcc);
  std::mt19937 rng(11);
  double worst = 0.0;
  for (int i = 0; i < 500; ++i) {
    const glm::dvec3 u(std::uniform_real_distribution<double>(4.0, 15.0)(rng),
                       std::uniform_real_distribution<double>(4.0, 15.0)(rng),
                       std::uniform_real_distribution<double>(4.0, 15.0)(rng));
    worst = std::max(worst, std::abs(spline.value(u) - q(u)));
  }
  EXPECT_LT(worst, 1e-5);
  EXPECT_THROW(quasiInterpolate(fcc), InputError);
}

// Quasi-interpolation overshoots at a sharp edge: an integer texel type
// saturates there, and says how often; f32 keeps every value.
TEST(FccResampling, IntegerTexelsReportSaturation) {
  Volume edge = Volume::allocate({16, 16, 16}, ScalarType::U8, "edge");
  for (std::size_t i = 0; i < edge.voxelCount(); ++i) edge.setValueAtIndex(i, i % 16 < 8 ? 0 : 255);
  FccResampleStats stats;
  resampleToFcc(edge, {}, &stats);
  EXPECT_GT(stats.saturated, 0u);
  FccResampleOptions asFloat;
  asFloat.type = ScalarType::F32;
  resampleToFcc(edge, asFloat, &stats);
  EXPECT_EQ(stats.saturated, 0u);
}
