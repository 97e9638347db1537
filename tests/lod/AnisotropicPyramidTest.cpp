// Pyramids that do not halve every axis (microscopy's (1, 2, 2) scales keep
// z): each level's factor per axis read from its dims and spacing, the brick
// grid's parents, children and level-0 cells under those factors, the mean
// pyramid bound with the level's own fan-in, level selection by the longest
// side of a voxel, and lod::readLevel placing a level where the bricks
// sample it.
#include <gtest/gtest.h>

#include "support/BricksTestSupport.h"

#include <memory>
#include <unordered_map>

#include "tessera/core/Error.h"
#include "tessera/lod/BrickGrid.h"
#include "tessera/lod/BrickStreamer.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/lod/LevelScale.h"
#include "tessera/lod/LevelSelection.h"
#include "tessera/lod/ReadLevel.h"

using namespace tessera;

namespace {

constexpr glm::ivec3 kKeepZ{2, 2, 1};  // (1, 2, 2) in z, y, x order

// Sparse bright voxels over a dim, mostly empty background: bounds that
// forgot a level's fan-in, or that dropped a bright voxel, show.
std::shared_ptr<Volume> sparse(glm::ivec3 d) {
  auto v = std::make_shared<Volume>(Volume::allocate(d, ScalarType::U8));
  for (std::size_t i = 0; i < v->voxelCount(); ++i) {
    const std::size_t h = i * 2654435761u >> 9;
    v->setValueAtIndex(i, h % 997 == 0 ? 255.0 : h % 5 == 0 ? static_cast<double>(h % 7) : 0.0);
  }
  v->invalidateRange();
  v->setSpacing({0.4, 0.4, 2.5});
  return v;
}

lod::LevelInfo info(glm::ivec3 dims, glm::vec3 spacing) {
  return {.dims = dims, .spacing = spacing, .chunk = {}};
}

}  // namespace

TEST(AnisotropicPyramid, FactorsComeFromTheDimsAndTheSpacingDecidesOnlyWhereTheDimsAllowBoth) {
  // (1, 2, 2) with ceil and floor rounding, then an axis of one voxel that
  // the spacing says is halved, then one it says is kept.
  const std::vector<lod::LevelInfo> levels{info({45, 30, 7}, {1, 1, 3}),
                                           info({23, 15, 7}, {2, 2, 3}),
                                           info({11, 7, 7}, {4, 4, 3}), info({6, 4, 4}, {8, 8, 6})};
  const std::vector<glm::ivec3> f = lod::levelFactors(levels, "s");
  ASSERT_EQ(f.size(), 4u);
  EXPECT_EQ(f[0], glm::ivec3(1));
  EXPECT_EQ(f[1], glm::ivec3(2, 2, 1));
  EXPECT_EQ(f[2], glm::ivec3(2, 2, 1));
  EXPECT_EQ(f[3], glm::ivec3(2, 2, 2));
  EXPECT_EQ(lod::levelScales(f)[3], glm::ivec3(8, 8, 2));
  // One voxel along z: kept or halved alike by the dims; the spacing says.
  const std::vector<glm::ivec3> one = lod::levelFactors(
      {info({8, 8, 1}, {1, 1, 1}), info({4, 4, 1}, {2, 2, 1}), info({2, 2, 1}, {4, 4, 2})}, "s");
  EXPECT_EQ(one[1], glm::ivec3(2, 2, 1));
  EXPECT_EQ(one[2], glm::ivec3(2, 2, 2));
  // The dims win over a spacing that contradicts them.
  EXPECT_EQ(lod::levelFactors({info({8, 8, 8}, {1, 1, 1}), info({4, 4, 8}, {2, 2, 2})}, "s")[1],
            glm::ivec3(2, 2, 1));
  // A level that grows, or is not an integer reduction, names the level and axis.
  try {
    lod::levelFactors({info({64, 64, 16}, {1, 1, 1}), info({32, 40, 16}, {2, 1.6f, 1})},
                      "odd.ome.zarr");
    ADD_FAILURE() << "64 -> 40 accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("odd.ome.zarr: level 1 (32x40x16) does not reduce level "
                                         "0 (64x64x16) by an integer factor along y"),
              std::string::npos)
        << e.what();
  }
}

TEST(AnisotropicPyramid, GridParentsChildrenAndCellsFollowEachLevelsFactors) {
  const auto v = sparse({50, 37, 21});
  const lod::InCoreMultiresSource src(v, 8, kKeepZ);
  // z kept at every level: 50x37x21, 25x19x21, 13x10x21, 7x5x21.
  ASSERT_EQ(src.levelCount(), 4);
  EXPECT_EQ(src.levelInfo(3).dims, glm::ivec3(7, 5, 21));
  const lod::BrickGrid grid = lod::BrickGrid::of(src, 4);
  for (int l = 1; l < grid.levelCount(); ++l) {
    EXPECT_EQ(grid.factor(l), kKeepZ);
    EXPECT_EQ(grid.scale(l), glm::ivec3(1 << l, 1 << l, 1));
    EXPECT_EQ(grid.fanIn(l), 4);
  }
  // Every level-0 cell lies in exactly the brick its ancestorOf names, at
  // every level, inside that brick's corners; and each brick's children
  // are the bricks whose parent it is.
  const glm::ivec3 cells = grid.bricks(0);
  for (int l = 0; l < grid.levelCount(); ++l) {
    SCOPED_TRACE(l);
    for (int z = 0; z < cells.z; ++z)
      for (int y = 0; y < cells.y; ++y)
        for (int x = 0; x < cells.x; ++x) {
          const glm::ivec3 c(x, y, z);
          const lod::BrickKey k = grid.ancestorOf(c, l);
          ASSERT_TRUE(grid.contains(k));
          const glm::dvec3 lo = grid.lowerCorner(k), hi = grid.upperCorner(k);
          const glm::dvec3 cellLo(c * 4);
          EXPECT_TRUE(glm::all(glm::greaterThanEqual(cellLo, lo)) &&
                      glm::all(glm::lessThan(cellLo, hi)));
          if (l > 0) {
            EXPECT_EQ(grid.parent(grid.ancestorOf(c, l - 1)), k);
          }
        }
    const glm::ivec3 n = grid.bricks(l);
    std::uint64_t childCount = 0;
    for (int z = 0; z < n.z; ++z)
      for (int y = 0; y < n.y; ++y)
        for (int x = 0; x < n.x; ++x) {
          const lod::BrickKey k{l, {x, y, z}};
          for (const lod::BrickKey& child : grid.children(k)) {
            EXPECT_EQ(grid.parent(child), k);
            ++childCount;
          }
        }
    if (l > 0) {
      EXPECT_EQ(childCount, grid.brickCount(l - 1)) << "each brick has one parent";
    }
  }
  // The level-3 brick over cell (0, 0, 2) spans 32 level-0 voxels in x and
  // y and 4 in z (z kept).
  const lod::BrickKey top = grid.ancestorOf({0, 0, 2}, 3);
  EXPECT_EQ(top.brick, glm::ivec3(0, 0, 2));
  EXPECT_EQ(grid.lowerCorner(top), glm::dvec3(0, 0, 8));
  EXPECT_EQ(grid.upperCorner(top), glm::dvec3(32, 32, 12));
}

// Every brick's stored range lies within the bound its ancestors give with
// the levels' own fan-in (4 here), and that bound is tighter than the
// factor-2 one (8 a level) over empty space.
TEST(AnisotropicPyramid, MeanPyramidBoundWithTheLevelsFanInHoldsForEveryBrick) {
  const auto source = std::make_shared<lod::InCoreMultiresSource>(sparse({70, 45, 24}), 8, kKeepZ);
  ASSERT_TRUE(source->meanPyramid());
  const lod::BrickGrid grid = lod::BrickGrid::of(*source, 8);
  const lod::StoredMapping identity = lod::StoredMapping::of(source->shape());
  auto ranges = test::storedRanges(*source, grid, identity);
  int checked = 0, dimAncestorOfBright = 0;
  for (int l = 0; l + 1 < grid.levelCount(); ++l) {
    const glm::ivec3 n = grid.bricks(l);
    for (int z = 0; z < n.z; ++z)
      for (int y = 0; y < n.y; ++y)
        for (int x = 0; x < n.x; ++x) {
          const lod::BrickKey k{l, {x, y, z}};
          const lod::BrickRange r = ranges[l][k.id()];
          std::vector<int> upward;  // the fan-ins of levels l + 1 .. a.level
          for (lod::BrickKey a = grid.parent(k); a.level < grid.levelCount(); a = grid.parent(a)) {
            upward.push_back(grid.fanIn(a.level));
            const std::vector<int> fromA(upward.rbegin(), upward.rend());
            const lod::BrickRange ar = ranges[a.level][a.id()];
            const lod::BrickRange bound = lod::meanPyramidBound(ar, fromA, 255);
            EXPECT_LE(bound.min, r.min) << "level " << l << " from " << a.level;
            EXPECT_GE(bound.max, r.max) << "level " << l << " from " << a.level;
            if (r.max == 255 && ar.max < 64) ++dimAncestorOfBright;
            ++checked;
          }
        }
  }
  EXPECT_GT(checked, 100);
  EXPECT_GT(dimAncestorOfBright, 0) << "the volume should hold bright voxels averaged away";
  EXPECT_EQ(lod::meanPyramidBound({0, 0}, std::vector<int>{4, 4}, 255).max, 20);
  EXPECT_EQ(lod::meanPyramidBound({0, 0}, 2, 255).max, 72);  // factor 2 on every axis
}

TEST(AnisotropicPyramid, LevelSelectionWeighsTheLongestSideOfALevelsVoxel) {
  // Level-0 voxels 1 x 1 x 4 mm; z kept: a level-2 voxel is 4 x 4 x 4 mm,
  // as long as a level-0 one. A view wanting voxels of at most 4 mm keeps
  // every brick at level 2 (its voxels are no longer than level 0's).
  const std::vector<glm::ivec3> dims{{64, 64, 16}, {32, 32, 16}, {16, 16, 16}};
  const lod::BrickGrid grid(dims, {glm::ivec3(1), kKeepZ, kKeepZ}, 16);
  lod::LodView view;
  view.spacing = {1.0, 1.0, 4.0};
  view.orthographic = true;
  view.pixelSize = 4.0;
  const auto all = [](const lod::BrickKey&) { return true; };
  const lod::LodSelection s = lod::selectBricks(grid, view, all, 1000);
  ASSERT_EQ(s.bricksPerLevel.size(), 3u);
  EXPECT_EQ(s.bricksPerLevel[2], 1);
  // Finer pixels: level 0 everywhere, 16 bricks (4 x 4 x 1).
  view.pixelSize = 1.0;
  EXPECT_EQ(lod::selectBricks(grid, view, all, 1000).bricksPerLevel[0], 16);
}

TEST(AnisotropicPyramid, ReadLevelPlacesEachLevelWhereTheBricksSampleIt) {
  auto v = sparse({45, 37, 23});
  v->setOrigin({-3.0, 7.5, 11.0});
  const lod::InCoreMultiresSource source(v, 8, kKeepZ);
  ASSERT_EQ(source.levelCount(), 4);
  const Volume& shape = source.shape();
  for (int l = 0; l < source.levelCount(); ++l) {
    SCOPED_TRACE(l);
    const Volume level = lod::readLevel(source, l);
    const glm::ivec3 d = source.levelInfo(l).dims;
    ASSERT_EQ(level.dims(), d);
    const glm::dvec3 s(lod::levelScale(source, l));
    EXPECT_EQ(s, glm::dvec3(1 << l, 1 << l, 1));
    for (const glm::ivec3 i : {glm::ivec3(0), d - 1, glm::ivec3(d.x / 2, 0, d.z - 1)}) {
      const glm::dvec3 want = shape.worldOf((glm::dvec3(i) + 0.5) * s - 0.5);
      const glm::dvec3 got = level.worldOf(glm::dvec3(i));
      EXPECT_NEAR(glm::length(got - want), 0.0, 1e-9);
    }
    // lod::downsample put its voxels there too.
    EXPECT_NEAR(glm::length(level.origin() - source.level(l).origin()), 0.0, 1e-9);
    EXPECT_NEAR(glm::length(level.spacing() - source.level(l).spacing()), 0.0, 1e-9);
  }
}
