// The virtual head16:8192 (1 TiB of u16, never held): every level is
// computed brick by brick, and each stored brick (apron included) equals the
// level's voxels computed one by one, i.e. the bricks' address maths against
// direct indexing, at all ten levels.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "tessera/lod/BrickGrid.h"
#include "tessera/lod/ProceduralMultiresSource.h"

namespace tessera::lod {
namespace {

// Brick `key`'s stored voxel (x, y, z) (0 .. B+1, the apron replicating the
// level's faces) against the level's voxel computed directly.
void expectBrickEqualsDirect(const ProceduralMultiresSource& src, const BrickGrid& grid,
                             const BrickKey& key, const StoredMapping& mapping) {
  const StoredBrick brick = readStoredBrick(src, grid, key, mapping);
  const int s = grid.stored();
  ASSERT_EQ(brick.count(), static_cast<std::size_t>(s) * s * s);
  const glm::ivec3 dims = grid.dims(key.level);
  const glm::ivec3 first = key.brick * grid.brickSize() - 1;
  std::size_t i = 0, differing = 0;
  for (int z = 0; z < s; ++z) {
    for (int y = 0; y < s; ++y) {
      for (int x = 0; x < s; ++x, ++i) {
        const glm::ivec3 v = glm::clamp(first + glm::ivec3(x, y, z), glm::ivec3(0), dims - 1);
        differing += mapping.raw(brick.value(i)) != src.levelValue(key.level, v);
      }
    }
  }
  EXPECT_EQ(differing, 0u) << "level " << key.level << " brick " << key.brick.x << ","
                           << key.brick.y << "," << key.brick.z;
}

TEST(VirtualHead, StoredBricksAtEveryLevelEqualTheLevelComputedDirectly) {
  const ProceduralMultiresSource src("head16:8192");
  EXPECT_EQ(src.shape().voxelCount(), 1ull << 39);  // 1 TiB of u16, never allocated
  ASSERT_EQ(src.levelCount(), 10);                  // 8192 .. 16
  const BrickGrid grid = BrickGrid::of(src, 32);
  const StoredMapping mapping = StoredMapping::of(src.shape());
  ASSERT_EQ(mapping.bits, 16);
  for (int level = 0; level < src.levelCount(); ++level) {
    EXPECT_EQ(src.levelInfo(level).dims, glm::ivec3(8192 >> level));
    const glm::ivec3 n = grid.bricks(level);
    // A corner brick (apron replicated on three faces), the brick at the
    // centre (inside the head), and the last one.
    for (const glm::ivec3 b : {glm::ivec3(0), n / 2, n - 1}) {
      expectBrickEqualsDirect(src, grid, {level, b}, mapping);
    }
  }
}

// head16 levels >= 1 are band-limited: a noise component whose period spans
// fewer than 4 of the level's voxels fades to its mean, so a level far
// coarser than the speckles holds no speckle at all (point sampling would
// alias them into bright single voxels), and level 0 is the field itself.
TEST(VirtualHead, CoarseLevelsFadeDetailFinerThanTheirVoxelsToItsMean) {
  const ProceduralMultiresSource src("head16:1024");
  // Level 0 is the field at the voxel centre.
  const glm::ivec3 v(500, 510, 520);
  EXPECT_EQ(src.levelValue(0, v),
            static_cast<double>(std::lround(src.value16At(glm::dvec3(v) + 0.5))));
  // Level 3 (8 voxels): the speckles (period 4.7 voxels at 1024^3) and the
  // 16-bit texture (period 8) are gone; inside the brain the level varies
  // only with the tissue texture (period 32: 4 voxels of level 3, kept).
  int brightLevel3 = 0, brightPoint = 0;
  for (int z = 56; z < 72; ++z) {
    for (int y = 56; y < 72; ++y) {
      for (int x = 56; x < 72; ++x) {
        const glm::dvec3 c = (glm::dvec3(x, y, z) + 0.5) * 8.0;
        brightLevel3 += src.levelValue(3, {x, y, z}) >= 250.0 * 257.0;
        brightPoint += src.value16At(c) >= 250.0 * 257.0;
      }
    }
  }
  EXPECT_GT(brightPoint, 40) << "point sampling keeps isolated speckle voxels";
  EXPECT_EQ(brightLevel3, 0);
}

}  // namespace
}  // namespace tessera::lod
