// reference::PyramidLevelReconstruction, the CPU twin of how bricks.glsl
// samples a coarser level over level 0's box: for a field linear in the
// voxel index, each level of the mean pyramid (lod::downsample, read with
// lod::readLevel) reconstructs the same field wherever its voxels are whole
// blocks; placed half a voxel off, a level would be off by half a voxel's
// slope. Level 0 is the volume's trilinear field everywhere.
#include <gtest/gtest.h>

#include <cmath>

#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/lod/ReadLevel.h"
#include "tessera/reference/Reconstruction.h"

namespace tessera {
namespace {

constexpr glm::dvec3 kSlope{3.0, 5.0, 7.0};  // per level-0 voxel

std::shared_ptr<Volume> linear(glm::ivec3 d) {
  auto v = std::make_shared<Volume>(Volume::allocate(d, ScalarType::F32, "linear"));
  for (int z = 0; z < d.z; ++z) {
    for (int y = 0; y < d.y; ++y) {
      for (int x = 0; x < d.x; ++x) {
        v->setValueAtIndex(v->index(x, y, z), 100.0 + glm::dot(kSlope, glm::dvec3(x, y, z)));
      }
    }
  }
  v->invalidateRange();
  return v;
}

TEST(PyramidLevelField, EveryLevelOfALinearFieldReconstructsItWhereItsBlocksAreWhole) {
  const glm::ivec3 d{45, 37, 23};
  const auto volume = linear(d);
  const lod::InCoreMultiresSource source(volume, 8);
  ASSERT_EQ(source.levelCount(), 4);
  const TrilinearReconstruction finest(*volume);
  for (int l = 0; l < source.levelCount(); ++l) {
    SCOPED_TRACE(l);
    const PyramidLevelReconstruction field(lod::readLevel(source, l), glm::ivec3(1 << l), d);
    EXPECT_EQ(field.dims(), d);
    const double f = double(1 << l);
    // Level-0 index x: inside the first and the last whole block's centres
    // (a partial block at an odd edge averages fewer voxels).
    const glm::dvec3 lo(f - 0.5);
    const glm::dvec3 hi = glm::floor(glm::dvec3(d) / f) * f - f / 2.0 - 0.5;
    int checked = 0;
    for (int k = 0; k <= 10; ++k) {
      const glm::dvec3 x = lo + (hi - lo) * glm::dvec3(k / 10.0, (10 - k) / 10.0, (k % 3) / 2.0);
      const glm::dvec3 p = (x + 0.5) / glm::dvec3(d);
      const double want = 100.0 + glm::dot(kSlope, x);
      EXPECT_NEAR(field.value(p), want, 1e-3) << x.x << "," << x.y << "," << x.z;
      EXPECT_NEAR(finest.value(p), want, 1e-3);
      ++checked;
    }
    EXPECT_EQ(checked, 11);
    // The gradient steps one level-0 voxel (the GPU's u_layoutVoxel): the
    // slope per texture unit is the slope per voxel times the dims.
    const glm::dvec3 g = field.gradient((lo + hi + 1.0) / (2.0 * glm::dvec3(d)));
    EXPECT_NEAR(g.x, kSlope.x * d.x, 1e-2);
    EXPECT_NEAR(g.y, kSlope.y * d.y, 1e-2);
    EXPECT_NEAR(g.z, kSlope.z * d.z, 1e-2);
  }
}

TEST(PyramidLevelField, LevelZeroIsTheTrilinearFieldAndOutsideTheBoxIsClamped) {
  const glm::ivec3 d{13, 9, 7};
  const auto volume = linear(d);
  const TrilinearReconstruction trilinear(*volume);
  const PyramidLevelReconstruction field(*volume, glm::ivec3(1), d);
  for (double t : {-0.2, 0.0, 0.013, 0.31, 0.5, 0.77, 0.999, 1.0, 1.3}) {
    const glm::dvec3 p(t, 1.0 - t, 0.5 * t);
    EXPECT_NEAR(field.value(p), trilinear.value(p), 1e-9) << t;
  }
  // With nearest, every point of a voxel's cell reads its value.
  const PyramidLevelReconstruction nearest(*volume, glm::ivec3(1), d, true);
  const NearestReconstruction cells(*volume);
  for (double t : {0.01, 0.2, 0.49, 0.51, 0.93}) {
    const glm::dvec3 p(t, 0.7 * t, 1.0 - t);
    EXPECT_NEAR(nearest.value(p), cells.value(p), 1e-9) << t;
  }
}

}  // namespace
}  // namespace tessera
