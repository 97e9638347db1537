// The reference's reconstruction is pluggable: the trilinear field of a
// volume, its central-difference gradient, and an analytic field rendered
// through the same ray caster.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "support/TestCameras.h"
#include "support/TestTransferFunctions.h"
#include "tessera/core/Camera.h"
#include "tessera/core/Error.h"
#include "tessera/io/Procedural.h"
#include "tessera/reference/CellLevels.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/Reconstruction.h"
#include "tessera/reference/ReferenceRaycaster.h"

using namespace tessera;

namespace {
// raw = 3x + 5y - 2z + 7 in voxel units: trilinear reproduces it exactly.
Volume ramp(glm::ivec3 d) {
  Volume v = Volume::allocate(d, ScalarType::F32, "ramp");
  for (int z = 0; z < d.z; ++z) {
    for (int y = 0; y < d.y; ++y) {
      for (int x = 0; x < d.x; ++x)
        v.setValueAtIndex(v.index(x, y, z), 3.0 * x + 5.0 * y - 2.0 * z + 7.0);
    }
  }
  return v;
}

// A constant field over the box: its image is computable by hand.
class ConstantField final : public Reconstruction {
 public:
  explicit ConstantField(double value) : value_(value) {}
  double value(glm::dvec3) const override { return value_; }
  glm::ivec3 dims() const override { return {8, 8, 8}; }
  int supportVoxels() const override { return 0; }

 private:
  double value_;
};
}  // namespace

TEST(Reconstruction, TrilinearReproducesALinearFieldAndItsGradient) {
  const glm::ivec3 d(9, 7, 6);
  const Volume v = ramp(d);
  const TrilinearReconstruction field(v);
  for (const glm::dvec3 voxel : {glm::dvec3(2.3, 3.7, 1.2), glm::dvec3(4.0, 3.0, 2.5)}) {
    const glm::dvec3 p = (voxel + 0.5) / glm::dvec3(d);
    EXPECT_NEAR(field.value(p), 3.0 * voxel.x + 5.0 * voxel.y - 2.0 * voxel.z + 7.0, 1e-9);
    // Per texture-space unit: the per-voxel slope times dims.
    const glm::dvec3 g = field.gradient(p);
    EXPECT_NEAR(g.x, 3.0 * d.x, 1e-6);
    EXPECT_NEAR(g.y, 5.0 * d.y, 1e-6);
    EXPECT_NEAR(g.z, -2.0 * d.z, 1e-6);
  }
}

TEST(Reconstruction, ReferenceWithTheTrilinearFieldIsTheDefaultReference) {
  const Volume v = makeSheppLogan({24, 24, 24});
  Camera cam = test::orbitCamera(v, 25, 0);
  const TransferFunction tf = TransferFunction::preset("mr-default");
  const RenderSettings s;
  const Image a = renderReference(v, tf, cam, s, 64, 64);
  const Image b = renderReference(v, TrilinearReconstruction(v), tf, cam, s, 64, 64);
  EXPECT_TRUE(std::isinf(psnr(a, b)));
}

// Orthographic view straight down an axis of a constant field: every ray
// crosses the same length, so every covered pixel is 1 - (1 - a)^n with the
// sample count n the reference takes.
TEST(Reconstruction, AnalyticFieldRendersAsComputedByHand) {
  Volume box = Volume::shapeOnly({8, 8, 8}, ScalarType::U8);
  box.setWindow({0.0, 1.0});
  const TransferFunction tf = test::oneColorTf({1.0, 1.0, 1.0}, {{0.0, 0.1}, {1.0, 0.1}});
  Camera cam;
  cam.projection = Projection::Orthographic;
  cam.frame(box);
  cam.zoom = 2.0;  // only the box's face in view
  RenderSettings s;
  s.ertThreshold = 1.0;
  s.background = {0.0, 0.0, 0.0, 1.0};
  const Image img = renderReference(box, ConstantField(0.5), tf, cam, s, 16, 16);
  const double ds = s.stepVoxels;                             // spacing 1
  const int n = static_cast<int>(std::ceil(8.0 / ds - 0.5));  // samples at (k + 0.5) ds < 8
  const double a = tf.correctedOpacity(0.5, ds, 1.0);
  const double alpha = 1.0 - std::pow(1.0 - a, n);
  EXPECT_NEAR(img.pixel(8, 8)[0], std::lround(255.0 * alpha), 1.0);
}

// A streamed frame's cells: levelAt finds the cell as bricks.glsl does (the
// last, partial cell takes p = 1), and sampleLevel is the field
// PyramidLevelReconstruction samples, read without a double copy.
TEST(CellLevels, LevelAtFollowsTheCellsAndSampleLevelIsThePyramidField) {
  CellLevels cells{{40, 20, 10}, 16, {3, 2, 1}, {0, 1, 2, 0, 1, -1}};
  EXPECT_EQ(cells.levelAt({0.0, 0.0, 0.5}), 0);
  EXPECT_EQ(cells.levelAt({16.5 / 40.0, 0.1, 0.5}), 1);
  EXPECT_EQ(cells.levelAt({1.0, 0.1, 0.5}), 2);    // cell 2 is partial: x in [32, 40]
  EXPECT_EQ(cells.levelAt({1.5, 2.0, -1.0}), -1);  // clamped to the box: cell (2, 1, 0)
  EXPECT_EQ(cells.cellsPerLevel(), (std::vector<int>{2, 2, 1, 1}));
  EXPECT_TRUE(cells.mixed());
  const Volume level = ramp({10, 5, 3});
  const PyramidLevelReconstruction field(level, {4, 4, 4}, {40, 20, 10});
  for (const glm::dvec3 p :
       {glm::dvec3(0.3, 0.6, 0.2), glm::dvec3(0.97, 0.01, 0.99), glm::dvec3(-0.2, 1.3, 0.5)}) {
    EXPECT_NEAR(sampleLevel(level, {4, 4, 4}, {40, 20, 10}, p), field.value(p), 1e-9) << p.x;
  }
}

// A single-channel frame that mixes levels: each point reads the level its
// cell shows (a transparent cell the level named for it), gradients step
// across cells as the GPU's central differences do, and a cell whose level
// is not read is an error naming it.
TEST(CellLevels, CellLevelsReconstructionReadsEachCellsLevel) {
  const glm::ivec3 finest{40, 20, 10};
  CellLevels cells{finest, 16, {3, 2, 1}, {0, 1, 1, 0, -1, 1}};
  const Volume level0 = ramp(finest);
  Volume level1 = ramp({20, 10, 5});
  for (std::size_t i = 0; i < level1.voxelCount(); ++i) {
    level1.setValueAtIndex(i, 1000.0 + level1.valueAtIndex(i));  // tells the levels apart
  }
  auto f0 = std::make_shared<PyramidLevelReconstruction>(level0, glm::ivec3(1), finest);
  auto f1 = std::make_shared<PyramidLevelReconstruction>(level1, glm::ivec3(2), finest);
  const CellLevelsReconstruction mixed(cells, {f0, f1}, 0);
  EXPECT_EQ(mixed.dims(), finest);
  EXPECT_EQ(mixed.supportVoxels(), 2);
  for (const glm::dvec3 p : {glm::dvec3(0.1, 0.2, 0.5), glm::dvec3(0.5, 0.3, 0.4),
                             glm::dvec3(0.9, 0.9, 0.5), glm::dvec3(0.5, 0.9, 0.5)}) {
    const int l = cells.levelAt(p);
    const double expected = l == 1 ? f1->value(p) : f0->value(p);  // -1 reads level 0
    EXPECT_EQ(mixed.value(p), expected) << p.x << " " << p.y << " level " << l;
  }
  // Across the side x = 16 between cell 0 (level 0) and cell 1 (level 1):
  // the difference quotient of the two levels' values, as the GPU takes it.
  const glm::dvec3 side(16.0 / 40.0, 0.2, 0.5);
  const double h = 1.0 / 40.0;
  EXPECT_NEAR(
      mixed.gradient(side).x,
      (f1->value(side + glm::dvec3(h, 0, 0)) - f0->value(side - glm::dvec3(h, 0, 0))) / (2.0 * h),
      1e-9);
  try {
    const CellLevelsReconstruction missing(cells, {f0, nullptr}, 0);
    ADD_FAILURE() << "level 1 is shown but not read";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "cell levels: 3 cells show level 1, which is not read");
  }
  EXPECT_THROW(CellLevelsReconstruction(cells, {nullptr, f1}, 0), InputError);  // transparent
  cells.levels.pop_back();
  EXPECT_THROW(CellLevelsReconstruction(cells, {f0, f1}, 0), InputError);
}
