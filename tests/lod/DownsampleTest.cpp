#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "tessera/core/Error.h"
#include "tessera/lod/Downsample.h"

using namespace tessera;

TEST(Downsample, AveragesEachBoxAndScalesSpacing) {
  Volume v = Volume::allocate({5, 4, 3}, ScalarType::U16);
  v.setSpacing({1.0, 2.0, 3.0});
  for (std::size_t i = 0; i < v.voxelCount(); ++i)
    v.setValueAtIndex(i, static_cast<double>(i * 7 % 50));
  const Volume d = lod::downsample(v, {2, 2, 1});
  EXPECT_EQ(d.dims(), glm::ivec3(3, 2, 3));
  EXPECT_EQ(d.spacing(), glm::dvec3(2.0, 4.0, 3.0));
  EXPECT_EQ(d.type(), ScalarType::U16);
  for (int z = 0; z < 3; ++z) {
    for (int y = 0; y < 2; ++y) {
      for (int x = 0; x < 3; ++x) {
        double sum = 0;
        int n = 0;
        for (int yy = 2 * y; yy < std::min(4, 2 * y + 2); ++yy) {
          for (int xx = 2 * x; xx < std::min(5, 2 * x + 2); ++xx) {
            sum += v.valueAt(xx, yy, z);
            ++n;
          }
        }
        EXPECT_EQ(d.valueAt(x, y, z), std::round(sum / n)) << x << "," << y << "," << z;
      }
    }
  }
}

TEST(Downsample, FactorOneIsIdentityAndBadFactorsThrow) {
  Volume v = Volume::allocate({3, 3, 3}, ScalarType::F32);
  for (std::size_t i = 0; i < v.voxelCount(); ++i)
    v.setValueAtIndex(i, 0.25 * static_cast<double>(i));
  const Volume d = lod::downsample(v, {1, 1, 1});
  for (std::size_t i = 0; i < v.voxelCount(); ++i) EXPECT_EQ(d.valueAtIndex(i), v.valueAtIndex(i));
  EXPECT_THROW(lod::downsample(v, {0, 1, 1}), InputError);
}
