// The expected cost of each row of a ray-cast frame (RowCosts): rows whose
// rays enter the volume's box against a box of known projection, and the
// arithmetic that sizes strips by it against direct sums.
#include <gtest/gtest.h>

#include <cmath>

#include "tessera/core/Camera.h"
#include "tessera/core/Error.h"
#include "tessera/render/RowCosts.h"

using namespace tessera;

namespace {

// An orthographic camera straight down an axis: a cube of side 1 shows as a
// centred square, 1 / (2 x orthoHalfHeight) of the height on each side.
Camera straightOrtho() {
  Camera cam;
  cam.projection = Projection::Orthographic;
  cam.frame(glm::dvec3(1.0));
  return cam;
}

}  // namespace

TEST(RowCosts, RowsAcrossTheBoxWeighTheirEnteringRaysOthersTheMissWeight) {
  const Camera cam = straightOrtho();
  const int size = 200;
  const render::RowCosts costs(cam, glm::dvec3(1.0), size, size, render::Footprint::VolumeBox,
                               size);
  const double side = size / (2.0 * cam.orthoHalfHeight());  // the square's side in pixels
  const double lo = 0.5 * (size - side), hi = 0.5 * (size + side);
  int across = 0;
  for (int r = 0; r < size; ++r) {
    const double centre = r + 0.5;
    if (centre < lo + 1.0 || centre > hi - 1.0) {
      if (centre < lo - 1.0 || centre > hi + 1.0) {
        EXPECT_DOUBLE_EQ(costs.row(r), render::RowCosts::kMissWeight * size) << "row " << r;
      }
      continue;  // rows at the square's edges: either
    }
    ++across;
    // The square's columns enter the box, within a pixel at either side.
    const double expected = side + render::RowCosts::kMissWeight * (size - side);
    EXPECT_NEAR(costs.row(r), expected, 2.0 * (1.0 - render::RowCosts::kMissWeight)) << "row " << r;
  }
  EXPECT_GT(across, size / 3) << "the square covers a good part of the rows";
}

TEST(RowCosts, FewerColumnsSampledGiveAboutTheSameRows) {
  Camera cam;
  cam.azimuthDeg = 35;
  cam.elevationDeg = 20;
  cam.frame(glm::dvec3(1.0, 1.2, 0.8));
  const render::RowCosts every(cam, glm::dvec3(1.0, 1.2, 0.8), 256, 192,
                               render::Footprint::VolumeBox, 256);
  const render::RowCosts sampled(cam, glm::dvec3(1.0, 1.2, 0.8), 256, 192,
                                 render::Footprint::VolumeBox, 32);
  for (int r = 0; r < 192; ++r) {
    EXPECT_NEAR(sampled.row(r), every.row(r), 256.0 / 32.0 * 2.0) << "row " << r;
  }
  EXPECT_NEAR(sampled.weight(0.0, 1.0), every.weight(0.0, 1.0), 0.02 * every.weight(0.0, 1.0));
}

TEST(RowCosts, WeightsAndReachAgreeWithDirectSums) {
  Camera cam;
  cam.azimuthDeg = 20;
  cam.elevationDeg = -15;
  cam.frame(glm::dvec3(1.0));
  const int h = 97;
  const render::RowCosts costs(cam, glm::dvec3(1.0), 120, h);
  const auto direct = [&](int a, int b) {
    double sum = 0.0;
    for (int r = a; r < b; ++r) sum += costs.row(r);
    return sum;
  };
  EXPECT_NEAR(costs.weight(0.0, 1.0), direct(0, h), 1e-9);
  EXPECT_NEAR(costs.weight(10.0 / h, 40.0 / h), direct(10, 40), 1e-9);
  EXPECT_EQ(costs.weight(0.5, 0.5), 0.0);
  for (int start : {0, 5, 30, 48, 90, 96}) {
    for (double w : {1.0, 50.0, 400.0, 2000.0, 1e9}) {
      const double to = costs.reach(static_cast<double>(start) / h, w);
      const int end = static_cast<int>(std::lround(to * h));
      ASSERT_GT(end, start) << "at least one row";
      ASSERT_LE(end, h);
      if (end < h) {
        EXPECT_GE(direct(start, end), w) << "from row " << start << ", weight " << w;
      }
      if (end > start + 1) {
        EXPECT_LT(direct(start, end - 1), w) << "the first row end reaching it";
      }
      EXPECT_NEAR(costs.weight(static_cast<double>(start) / h, to), direct(start, end), 1e-9);
    }
  }
  EXPECT_EQ(costs.reach(1.0, 10.0), 1.0);
  EXPECT_THROW(render::RowCosts(cam, glm::dvec3(1.0), 0, 10), tessera::InputError);
}

// The view-aligned slicer's proxy: a cube of the box's diagonal turned with
// the view, so straight on (orthographic) a centred square of that side,
// at any angle.
TEST(RowCosts, TheViewCubeIsASquareOfTheDiagonalAtAnyAngle) {
  const int size = 200;
  const glm::dvec3 extent(1.0, 0.6, 0.8);
  for (double azimuth : {0.0, 35.0, 80.0}) {
    Camera cam;
    cam.projection = Projection::Orthographic;
    cam.azimuthDeg = azimuth;
    cam.elevationDeg = 25.0;
    cam.frame(extent);
    cam.zoom = 0.5;  // the whole cube in view
    const render::RowCosts costs(cam, extent, size, size, render::Footprint::ViewCube, size);
    const double side = size * glm::length(extent) / (2.0 * cam.orthoHalfHeight());
    ASSERT_LT(side, size - 4.0);
    const double lo = 0.5 * (size - side), hi = 0.5 * (size + side);
    for (int r = 0; r < size; ++r) {
      const double centre = r + 0.5;
      if (centre < lo - 1.0 || centre > hi + 1.0) {
        EXPECT_DOUBLE_EQ(costs.row(r), render::RowCosts::kMissWeight * size) << "row " << r;
      } else if (centre > lo + 1.0 && centre < hi - 1.0) {
        EXPECT_NEAR(costs.row(r), side + render::RowCosts::kMissWeight * (size - side), 2.0)
            << "azimuth " << azimuth << ", row " << r;
      }
    }
    // The box itself covers less.
    const render::RowCosts box(cam, extent, size, size, render::Footprint::VolumeBox, size);
    EXPECT_LT(box.weight(0.0, 1.0), costs.weight(0.0, 1.0));
  }
}
