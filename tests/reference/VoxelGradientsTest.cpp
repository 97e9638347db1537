// The precomputed gradient's field (reference/VoxelGradients.h): away from
// the outermost half voxel, the trilinear interpolation of per-voxel central
// differences is the central difference of the trilinear field, up to the
// 8-bit quantisation of the differences.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "tessera/io/Procedural.h"
#include "tessera/reference/Reconstruction.h"
#include "tessera/reference/VoxelGradients.h"

using namespace tessera;

namespace {

// Deterministic points inside the box, at continuous voxel coordinates
// (centres at integers) in [margin, d - 1 - margin]: margin 0 is half a
// voxel from the faces.
template <class Visit>
void interiorPoints(glm::ivec3 d, double margin, Visit visit) {
  for (int k = 0; k < 2000; ++k) {
    const glm::dvec3 r(std::fmod(0.6180339887 * (k + 1), 1.0),
                       std::fmod(0.4142135624 * (k + 7), 1.0),
                       std::fmod(0.7320508076 * (k + 3), 1.0));
    visit((0.5 + margin + r * (glm::dvec3(d) - 1.0 - 2.0 * margin)) / glm::dvec3(d));
  }
}

}  // namespace

TEST(VoxelGradients, RampDifferencesQuantiseExactlyAndMatchCentralDifferences) {
  // raw = 3x - 2y + 0z (u8 range): every interior difference is (3, -2, 0).
  const glm::ivec3 d{12, 10, 9};
  Volume v = Volume::allocate(d, ScalarType::F32, "ramp");
  for (int z = 0; z < d.z; ++z)
    for (int y = 0; y < d.y; ++y)
      for (int x = 0; x < d.x; ++x) v.setValueAtIndex(v.index(x, y, z), 3.0 * x - 2.0 * y + 40.0);
  const VoxelGradients g = computeVoxelGradients(v);
  EXPECT_EQ(g.at(5, 5, 5), glm::dvec3(3.0, -2.0, 0.0));
  // Clamped at the face: (v1 - v0) / 2 = 1.5, 63.5 codes of 3/127: rounded.
  EXPECT_NEAR(g.at(0, 5, 5).x, 1.5, 0.5 * g.step.x);
  const TrilinearReconstruction field(v);
  const VoxelGradientReconstruction pre(field, g);
  // A voxel from the faces only interior differences interpolate.
  interiorPoints(d, 1.0, [&](glm::dvec3 p) {
    const glm::dvec3 a = field.gradient(p);
    const glm::dvec3 b = pre.gradient(p);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(a[i], b[i], 1e-9) << i;
    EXPECT_EQ(pre.value(p), field.value(p));
  });
}

TEST(VoxelGradients, MatchesCentralDifferencesOfTheTrilinearFieldUpToQuantisation) {
  const Volume v = makeSheppLogan({24, 27, 21});
  const VoxelGradients g = computeVoxelGradients(v);
  const TrilinearReconstruction field(v);
  const VoxelGradientReconstruction pre(field, g);
  double worst = 0.0;
  interiorPoints(v.dims(), 0.0, [&](glm::dvec3 p) {
    const glm::dvec3 a = field.gradient(p);
    const glm::dvec3 b = pre.gradient(p);
    for (int i = 0; i < 3; ++i) {
      // Half a code per voxel difference, in per texture-space unit.
      const double bound = 0.5 * g.step[i] * v.dims()[i] + 1e-9;
      worst = std::max(worst, std::abs(a[i] - b[i]) / bound);
      EXPECT_LE(std::abs(a[i] - b[i]), bound) << i;
    }
  });
  std::printf("  [measured] worst |difference| / half a code: %.3f\n", worst);
  EXPECT_GT(worst, 0.0) << "the phantom's differences should not all quantise exactly";
}
