// The FCC lattice's storage, address maths, density and geometry.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <set>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "tessera/core/Error.h"
#include "tessera/lattice/FccVolume.h"

using namespace tessera;
using namespace tessera::lattice;

namespace {

Volume boxOf(glm::ivec3 dims) {
  Volume box = Volume::shapeOnly(dims, ScalarType::F32);
  box.setWindow({0.0, 1.0});
  return box;
}

// A value that identifies the point.
double tag(glm::ivec3 p) {
  return p.x + 100.0 * p.y + 10000.0 * p.z;
}

FccVolume tagged(glm::ivec3 grid) {
  FccVolume v = FccVolume::allocate(boxOf(grid), grid, ScalarType::F32);
  for (int k = 0; k < grid.z; ++k) {
    for (int j = 0; j < grid.y; ++j) {
      for (int i = (j + k) & 1; i < grid.x; i += 2) v.setValue({i, j, k}, tag({i, j, k}));
    }
  }
  return v;
}

}  // namespace

// Every lattice point of odd (and mixed) sizes, enumerated directly: index()
// is a bijection onto the non-padding texels, pointAt() inverts it, and the
// only other texels are one padding texel per odd row of an odd-width grid.
TEST(FccVolume, PackingIndexAndInverseMatchDirectEnumerationForOddSizes) {
  for (const glm::ivec3 grid : {glm::ivec3(3, 5, 7), glm::ivec3(5, 5, 5), glm::ivec3(7, 4, 3),
                                glm::ivec3(2, 3, 9), glm::ivec3(9, 9, 2), glm::ivec3(41, 41, 41)}) {
    const FccVolume v = FccVolume::allocate(boxOf(grid), grid, ScalarType::U8);
    const glm::ivec3 packed = v.packed().dims();
    EXPECT_EQ(packed, glm::ivec3((grid.x + 1) / 2, grid.y, grid.z));
    std::set<std::size_t> used;
    std::uint64_t points = 0;
    for (int k = 0; k < grid.z; ++k) {
      for (int j = 0; j < grid.y; ++j) {
        for (int i = 0; i < grid.x; ++i) {
          if (!FccVolume::isLatticePoint({i, j, k})) continue;
          ++points;
          const std::size_t index = v.index({i, j, k});
          ASSERT_LT(index, v.packed().voxelCount());
          EXPECT_TRUE(used.insert(index).second) << "two points share texel " << index;
          EXPECT_EQ(v.pointAt(index), glm::ivec3(i, j, k));
          EXPECT_EQ(FccVolume::pointOf(FccVolume::texelOf({i, j, k})), glm::ivec3(i, j, k));
        }
      }
    }
    EXPECT_EQ(points, v.pointCount());
    std::uint64_t padding = 0;
    for (std::size_t t = 0; t < v.packed().voxelCount(); ++t) {
      if (used.count(t)) continue;
      ++padding;
      const glm::ivec3 p = v.pointAt(t);
      EXPECT_EQ(p.x, grid.x) << "padding texel holds a point just past the row";
      EXPECT_EQ((p.y + p.z) & 1, 1);
    }
    const std::uint64_t oddRows = (static_cast<std::uint64_t>(grid.y) * grid.z) / 2;
    EXPECT_EQ(padding, (grid.x & 1) ? oddRows : 0u);
    EXPECT_EQ(v.byteSize(), v.packed().voxelCount());  // u8
  }
}

// The boundary rule: in the grid a point reads itself; outside, the texel of
// its clamped position, which the padding makes a real point of the row.
TEST(FccVolume, ClampedValueReadsTheNearestBoundaryRowPoint) {
  const glm::ivec3 grid(5, 4, 3);
  const FccVolume v = tagged(grid);
  for (int k = -3; k < grid.z + 3; ++k) {
    for (int j = -3; j < grid.y + 3; ++j) {
      for (int i = -3; i < grid.x + 3; ++i) {
        const glm::ivec3 p(i, j, k);
        if (!FccVolume::isLatticePoint(p)) continue;
        const glm::ivec3 c = glm::clamp(p, glm::ivec3(0), grid - 1);
        glm::ivec3 expected = FccVolume::pointOf(FccVolume::texelOf(c));
        if (expected.x >= grid.x) expected.x -= 2;  // padding repeats the row's last point
        EXPECT_EQ(v.clampedValue(p), tag(expected)) << i << " " << j << " " << k;
        if (c == p) {
          EXPECT_EQ(v.clampedValue(p), tag(p));
        }
        EXPECT_LE(std::abs(expected.x - c.x), 1);
      }
    }
  }
}

TEST(FccVolume, SameDensityKeepsTheSampleCountAndHalfHalvesIt) {
  for (const glm::ivec3 n : {glm::ivec3(41), glm::ivec3(64), glm::ivec3(181, 217, 181)}) {
    const double cartesian = static_cast<double>(n.x) * n.y * n.z;
    const Volume box = boxOf(n);
    const FccVolume same =
        FccVolume::allocate(box, fccGridDims(n, FccDensity::Same), ScalarType::U8);
    const FccVolume half =
        FccVolume::allocate(box, fccGridDims(n, FccDensity::Half), ScalarType::U8);
    std::printf("[measured] %dx%dx%d (%.0f samples): %s; %s\n", n.x, n.y, n.z, cartesian,
                same.summary("same").c_str(), half.summary("half").c_str());
    EXPECT_NEAR(same.pointCount() / cartesian, 1.0, 0.04);
    EXPECT_EQ(half.pointCount(), static_cast<std::uint64_t>((cartesian + 1) / 2));
    EXPECT_EQ(half.gridDims(), n);
    // Bytes follow the samples (u8: one byte per texel, padding aside).
    EXPECT_NEAR(static_cast<double>(same.byteSize()) / cartesian, 1.0, 0.05);
    EXPECT_NEAR(static_cast<double>(half.byteSize()) / cartesian, 0.5, 0.02);
  }
  EXPECT_EQ(fccGridDims({41, 41, 41}, FccDensity::Same), glm::ivec3(52));
  EXPECT_EQ(fccGridDims({65, 65, 65}, FccDensity::Same),
            glm::ivec3(82));  // Sarfaraz & Shaban, Table 2
}

// The lattice keeps the source's index -> world affine: at half density its
// points are the source's voxel centres, and at any density the grid's box is
// the source's box.
TEST(FccVolume, GridToWorldPlacesTheLatticeInTheSourceBox) {
  Volume source = Volume::shapeOnly({20, 16, 12}, ScalarType::U8);
  glm::dmat4 affine = glm::rotate(glm::dmat4(1.0), 0.4, glm::dvec3(1, 2, 3));
  affine = glm::scale(affine, glm::dvec3(0.8, 1.1, 2.5));
  affine[3] = glm::dvec4(-30.0, 12.0, 7.5, 1.0);
  source.setIndexToWorld(affine);
  source.setWindow({0.0, 255.0});
  auto close = [](glm::dvec3 a, glm::dvec3 b) { return glm::length(a - b) < 1e-9; };
  const FccVolume half =
      FccVolume::allocate(source, fccGridDims(source.dims(), FccDensity::Half), ScalarType::U8);
  EXPECT_TRUE(close(half.worldOf({4, 6, 2}), source.worldOf({4, 6, 2})));
  const FccVolume same =
      FccVolume::allocate(source, fccGridDims(source.dims(), FccDensity::Same), ScalarType::U8);
  const glm::dvec3 d(same.gridDims());
  EXPECT_TRUE(close(same.worldOf(glm::dvec3(-0.5)), source.worldOf(glm::dvec3(-0.5))));
  EXPECT_TRUE(close(same.worldOf(d - 0.5), source.worldOf(glm::dvec3(source.dims()) - 0.5)));
  EXPECT_TRUE(close(same.textureOf(d - 0.5), glm::dvec3(1.0)));
  EXPECT_EQ(same.box().window().max, 255.0);
  EXPECT_TRUE(close(same.gridSpacing() * d, source.extent()));
}

TEST(FccVolume, RejectsDegenerateGridsAndUnknownDensities) {
  EXPECT_THROW(FccVolume::allocate(boxOf({4, 4, 4}), {1, 4, 4}, ScalarType::U8), InputError);
  EXPECT_EQ(parseFccDensity("same"), FccDensity::Same);
  EXPECT_EQ(parseFccDensity("half"), FccDensity::Half);
  EXPECT_THROW(parseFccDensity("double"), InputError);
  EXPECT_EQ(fccGridDims({1, 1, 1}, FccDensity::Half), glm::ivec3(2));
  const std::vector<float> tooFew(3);
  EXPECT_THROW(FccVolume::fromTexels(boxOf({4, 4, 4}), {4, 4, 4}, ScalarType::F32, tooFew),
               InputError);
}
