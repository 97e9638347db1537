// lod::readLevel: a whole pyramid level for the CPU reference of a streamed
// volume, its voxels those of readBox, placed where lod::BrickGrid and
// bricks.glsl put it (level-l voxel i centred on level-0 index
// (i + 0.5) 2^l - 0.5), which is where lod::downsample and the OME-Zarr
// writer's per-level translation put it too; errors name the level.
#include <gtest/gtest.h>

#include <cstring>

#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/io/ZarrWriter.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/lod/ReadLevel.h"
#include "tessera/lod/ZarrMultiresSource.h"

namespace tessera::lod {
namespace {

// Odd dims, anisotropic spacing and an oblique direction: an error along
// any axis, or in the order of scale and rotation, shows.
std::shared_ptr<Volume> oblique(glm::ivec3 d) {
  auto v = std::make_shared<Volume>(Volume::allocate(d, ScalarType::I16, "oblique"));
  for (std::size_t i = 0; i < v->voxelCount(); ++i) {
    v->setValueAtIndex(i, double(int(i * 2654435761u % 3000u)) - 1000.0);
  }
  v->invalidateRange();
  v->setSpacing({0.7, 1.2, 2.1});
  const double c = std::cos(0.4), s = std::sin(0.4);
  v->setDirection(glm::dmat3(glm::dvec3(c, s, 0.0), glm::dvec3(-s, c, 0.0), glm::dvec3(0, 0, 1)));
  v->setOrigin({-31.0, 4.5, 17.25});
  return v;
}

void expectNear(glm::dvec3 a, glm::dvec3 b) {
  EXPECT_NEAR(a.x, b.x, 1e-9);
  EXPECT_NEAR(a.y, b.y, 1e-9);
  EXPECT_NEAR(a.z, b.z, 1e-9);
}

// Every voxel centre of the level lies where the bricks layout samples it,
// and the level holds readBox's voxels.
void expectPlacedAsBricks(const MultiresSource& source) {
  const Volume& shape = source.shape();
  for (int l = 0; l < source.levelCount(); ++l) {
    SCOPED_TRACE(l);
    const Volume level = readLevel(source, l);
    const glm::ivec3 d = source.levelInfo(l).dims;
    ASSERT_EQ(level.dims(), d);
    ASSERT_EQ(level.type(), shape.type());
    const Volume box = source.readBox(l, {glm::ivec3(0), d});
    ASSERT_EQ(level.byteSize(), box.byteSize());
    EXPECT_EQ(std::memcmp(level.bytes().data(), box.bytes().data(), box.byteSize()), 0);
    const double f = double(1 << l);
    for (const glm::ivec3 i : {glm::ivec3(0), d - 1, glm::ivec3(d.x / 2, 0, d.z - 1)}) {
      expectNear(level.worldOf(glm::dvec3(i)), shape.worldOf((glm::dvec3(i) + 0.5) * f - 0.5));
    }
    EXPECT_EQ(level.window().min, shape.window().min);
    EXPECT_EQ(level.window().max, shape.window().max);
  }
}

TEST(ReadLevel, InCoreLevelsLieWhereTheBricksSampleThem) {
  const InCoreMultiresSource source(oblique({45, 37, 23}), 8);
  ASSERT_EQ(source.levelCount(), 4);  // 45x37x23, 23x19x12, 12x10x6, 6x5x3
  expectPlacedAsBricks(source);
  // lod::downsample puts its levels there too.
  for (int l = 1; l < source.levelCount(); ++l) {
    SCOPED_TRACE(l);
    const Volume level = readLevel(source, l);
    expectNear(level.origin(), source.level(l).origin());
    expectNear(level.spacing(), source.level(l).spacing());
  }
}

TEST(ReadLevel, StoreLevelsLieWhereTheBricksSampleThemAndWhereTheStoreSays) {
  const test::TempDir tmp;
  OmeZarrWriteOptions o;
  o.chunk = 16;
  writeOmeZarr(*oblique({45, 37, 23}), tmp / "o.ome.zarr", o);
  const auto source = ZarrMultiresSource::open((tmp / "o.ome.zarr").string());
  ASSERT_EQ(source->levelCount(), 3);  // 45x37x23, 23x19x12, 12x10x6
  expectPlacedAsBricks(*source);
  // The store's own per-level scale and translation (NGFF metadata) agree.
  for (int l = 1; l < source->levelCount(); ++l) {
    SCOPED_TRACE(l);
    const Volume level = readLevel(*source, l);
    const Volume own = source->readBox(l, {glm::ivec3(0), source->levelInfo(l).dims});
    expectNear(level.origin(), own.origin());
    expectNear(level.spacing(), own.spacing());
  }
}

TEST(ReadLevel, RefusesALevelOutsideThePyramidOrOverTheHostBudget) {
  const InCoreMultiresSource source(oblique({45, 37, 23}), 8);
  for (int bad : {-1, 4}) {
    try {
      readLevel(source, bad);
      ADD_FAILURE() << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("level " + std::to_string(bad) +
                                           " of in-core pyramid "
                                           "of 4 levels"),
                std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find("the pyramid has levels 0..3 (0 = the finest)"),
                std::string::npos)
          << e.what();
    }
  }
  EXPECT_EQ(levelBytes(source, 0), 45u * 37u * 23u * 2u);
  EXPECT_EQ(describeLevel(source, 1), "level 1 (23x19x12 i16, 10.2 KiB)");
  const test::BudgetOverride tight(40 << 10);  // level 0 is 74.8 KiB, level 1 fits
  try {
    readLevel(source, 0);
    ADD_FAILURE() << "level 0 read over the budget";
  } catch (const BudgetError& e) {
    EXPECT_NE(std::string(e.what()).find("level 0 (45x37x23 i16, 74.8 KiB) of in-core pyramid"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("budget is 40 KiB"), std::string::npos) << e.what();
  }
  EXPECT_EQ(readLevel(source, 1).dims(), glm::ivec3(23, 19, 12));
}

}  // namespace
}  // namespace tessera::lod
