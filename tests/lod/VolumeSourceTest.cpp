// The in-core volume source: its shape is the volume's, level (1,1,1) is the
// volume itself (shared, so a window change shows), other levels are the
// box-filtered reductions lod::downsample makes.
#include <gtest/gtest.h>

#include "tessera/lod/Downsample.h"
#include "tessera/lod/InCoreVolumeSource.h"

using namespace tessera;

namespace {

Volume ramp(glm::ivec3 dims) {
  Volume v = Volume::allocate(dims, ScalarType::U16);
  v.setSpacing({1.0, 1.5, 2.0});
  v.setOrigin({-3.0, 4.0, 7.0});
  for (std::size_t i = 0; i < v.voxelCount(); ++i)
    v.setValueAtIndex(i, static_cast<double>(i % 97));
  return v;
}

}  // namespace

TEST(VolumeSource, ShapeIsTheVolumesShapeAndGeometry) {
  const lod::InCoreVolumeSource source(ramp({9, 6, 5}));
  const Volume& shape = source.shape();
  EXPECT_EQ(shape.dims(), glm::ivec3(9, 6, 5));
  EXPECT_EQ(shape.type(), ScalarType::U16);
  EXPECT_EQ(shape.spacing(), glm::dvec3(1.0, 1.5, 2.0));
  EXPECT_EQ(shape.origin(), glm::dvec3(-3.0, 4.0, 7.0));
  EXPECT_EQ(shape.valueRange().max, 96.0);
}

TEST(VolumeSource, FullResolutionLevelIsTheSourcesOwnVolume) {
  lod::InCoreVolumeSource source(ramp({9, 6, 5}));
  const std::shared_ptr<Volume> full = source.level({1, 1, 1});
  EXPECT_EQ(full.get(), &source.volume());
  full->setWindow({10.0, 20.0});
  EXPECT_EQ(source.shape().window().min, 10.0);
}

TEST(VolumeSource, ReducedLevelsAreTheDownsampledVoxels) {
  const lod::InCoreVolumeSource source(ramp({9, 6, 5}));
  const std::shared_ptr<Volume> half = source.level({2, 1, 2});
  const Volume expected = lod::downsample(source.shape(), {2, 1, 2});
  ASSERT_EQ(half->dims(), glm::ivec3(5, 6, 3));
  EXPECT_EQ(half->spacing(), expected.spacing());
  EXPECT_EQ(half->origin(), expected.origin());
  for (std::size_t i = 0; i < half->voxelCount(); ++i) {
    ASSERT_EQ(half->valueAtIndex(i), expected.valueAtIndex(i)) << i;
  }
  EXPECT_NE(half.get(), &source.shape());
}
