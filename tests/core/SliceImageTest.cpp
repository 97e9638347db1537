// core/SliceImage.h, which `tessera slice` and the web page's slice views
// share: the radiological frame and letters of each plane whatever the
// storage order, square pixels over anisotropic voxels, and every pixel the
// value of the voxel it claims.
#include <gtest/gtest.h>

#include <cmath>

#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/core/SliceImage.h"
#include "tessera/core/Volume.h"

using namespace tessera;

namespace {

// A u8 volume whose voxel (x, y, z) holds (x + 3y + 7z) mod 251, so every
// voxel of a slice is told apart from its neighbours.
Volume numbered(glm::ivec3 dims, const glm::dmat3& direction, glm::dvec3 spacing) {
  Volume v = Volume::allocate(dims, ScalarType::U8);
  v.setDirection(direction);
  v.setSpacing(spacing);
  for (int z = 0; z < dims.z; ++z) {
    for (int y = 0; y < dims.y; ++y) {
      for (int x = 0; x < dims.x; ++x)
        v.setValueAtIndex(v.index(x, y, z), (x + 3 * y + 7 * z) % 251);
    }
  }
  v.invalidateRange();
  return v;
}

std::string letters(const SliceFrame& f) {
  return f.left + f.right + f.top + f.bottom;
}

}  // namespace

TEST(SliceImage, RasStorageGivesTheRadiologicalFrames) {
  const glm::dmat3 ras(1.0);
  const SliceFrame axial = sliceFrame(ras, 2);
  EXPECT_EQ(axial.plane, "axial");
  EXPECT_EQ(letters(axial), "RLAP");  // patient's left on the image's right, anterior up
  EXPECT_EQ(axial.colAxis, 0);
  EXPECT_TRUE(axial.colReversed);  // +x is the patient's right, shown on the left
  EXPECT_EQ(axial.rowAxis, 1);
  EXPECT_TRUE(axial.rowReversed);  // +y (anterior) up
  const SliceFrame coronal = sliceFrame(ras, 1);
  EXPECT_EQ(coronal.plane, "coronal");
  EXPECT_EQ(letters(coronal), "RLSI");
  const SliceFrame sagittal = sliceFrame(ras, 0);
  EXPECT_EQ(sagittal.plane, "sagittal");
  EXPECT_EQ(letters(sagittal), "APSI");  // anterior on the image's left
}

TEST(SliceImage, TheSameAnatomyStoredLpsGivesTheSameImage) {
  const glm::ivec3 d(6, 5, 4);
  const Volume ras = numbered(d, glm::dmat3(1.0), {1, 1, 1});
  // LPS storage of the same anatomy: x and y run the other way.
  Volume lps = Volume::allocate(d, ScalarType::U8);
  lps.setDirection(lpsToRas());
  for (int z = 0; z < d.z; ++z) {
    for (int y = 0; y < d.y; ++y) {
      for (int x = 0; x < d.x; ++x) {
        lps.setValueAtIndex(lps.index(d.x - 1 - x, d.y - 1 - y, z), ras.valueAt(x, y, z));
      }
    }
  }
  lps.invalidateRange();
  const ValueRange w{0.0, 250.0};
  for (int axis = 0; axis < 3; ++axis) {
    const SliceFrame fr = sliceFrame(ras.direction(), axis);
    const SliceFrame fl = sliceFrame(lps.direction(), axis);
    EXPECT_EQ(letters(fr), letters(fl)) << "axis " << axis;
    const int k = axis == 2 ? 1 : 2;
    const int kLps =
        axis == 2 ? k : d[axis] - 1 - k;  // x and y slices are counted from the other side
    EXPECT_EQ(sliceImage(ras, fr, k, w).rgba(), sliceImage(lps, fl, kLps, w).rgba())
        << "axis " << axis;
  }
}

TEST(SliceImage, EveryPixelIsTheNearestVoxelOnSquarePixels) {
  // 1 x 2 x 0.5 mm voxels: the axial image has square pixels of the finer
  // in-plane spacing (1 mm), two rows per y voxel.
  const glm::ivec3 d(7, 5, 3);
  const Volume v = numbered(d, glm::dmat3(1.0), {1.0, 2.0, 0.5});
  const SliceFrame f = sliceFrame(v.direction(), 2);
  const SliceRaster r = sliceRaster(f, d, v.spacing());
  EXPECT_EQ(r.pixelMm, 1.0);
  EXPECT_EQ(r.width, 7);
  EXPECT_EQ(r.height, 10);
  const ValueRange w{0.0, 255.0};
  const Image image = sliceImage(v, f, 1, w);
  ASSERT_EQ(image.width(), r.width);
  ASSERT_EQ(image.height(), r.height);
  for (int row = 0; row < r.height; ++row) {
    for (int col = 0; col < r.width; ++col) {
      const int x = d.x - 1 - col;      // patient's right (+x) on the left
      const int y = d.y - 1 - row / 2;  // anterior (+y) up, two rows per voxel
      EXPECT_EQ(image.pixel(col, row)[0], static_cast<int>(v.valueAt(x, y, 1)))
          << "pixel " << col << "," << row;
      EXPECT_EQ(image.pixel(col, row)[3], 255);
    }
  }
  EXPECT_EQ(sliceVoxelOf(3, 1.0, 2.0, 5, false), 1);
  EXPECT_EQ(sliceVoxelOf(3, 1.0, 2.0, 5, true), 3);
}

TEST(SliceImage, AnIndexOrAxisOutsideTheVolumeIsAnInputError) {
  const Volume v = numbered({4, 4, 4}, glm::dmat3(1.0), {1, 1, 1});
  const SliceFrame f = sliceFrame(v.direction(), 2);
  EXPECT_THROW(sliceImage(v, f, 4, {0, 1}), InputError);
  EXPECT_THROW(sliceImage(v, f, -1, {0, 1}), InputError);
  EXPECT_THROW(sliceFrame(v.direction(), 3), InputError);
}
