// The bricks page table tiled in 2D: its z-slices side by side, so a grid
// whose one-column table (cells.x x cells.y * cells.z) exceeds the 2D limit
// still fits. The address maths against direct indexing (the CPU layout and
// the float twin of bricks.glsl's pageTexel), and what the planner makes of
// the virtual 8192^3 u16 volume on ipad2 (2048^2), refused before.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tessera/gpu/DeviceProfile.h"
#include "tessera/layout/BricksLayout.h"

using namespace tessera;

namespace {

// bricks.glsl's pageTexel in single precision, as the shader computes it.
glm::vec2 shaderPageTexel(glm::vec3 cell, glm::vec3 cells, float tiles) {
  const float row = std::floor((cell.z + 0.5f) / tiles);
  const float col = cell.z - row * tiles;
  return glm::vec2(cell.x, cell.y) + glm::vec2(col, row) * glm::vec2(cells.x, cells.y);
}

gpu::DeviceLimits limitsOf(const std::string& profileName) {
  const gpu::DeviceProfile profile = gpu::DeviceProfile::find(profileName);
  gpu::DeviceCaps caps;
  caps.api = profile.api;
  caps.max2DTextureSize = 16384;
  caps.max3DTextureSize = profile.api == gpu::ApiLevel::Gles3 ? 2048 : 0;
  caps.maxTextureUnits = 32;
  caps.maxRenderbufferSize = 16384;
  if (profile.api == gpu::ApiLevel::Gles3) caps.extensions.insert("GL_EXT_texture_norm16");
  return gpu::effectiveLimits(profile, caps);
}

}  // namespace

TEST(BricksPageTable, TiledAddressOfEveryCellOfAGridTallerThanTheLimitIsItsOwn) {
  // 20 x 12 x 50 cells: one column would be 20 x 600 texels, over 128.
  const glm::ivec3 cells(20, 12, 50);
  const int maxSide = 128;
  const layout::MosaicLayout::Geometry g = layout::BricksLayout::pageTableGeometry(cells, maxSide);
  ASSERT_GT(g.tilesX, 1);
  ASSERT_GT(g.tilesY, 1);  // several rows of tiles
  ASSERT_LE(g.width(), maxSide);
  ASSERT_LE(g.height(), maxSide);
  std::vector<int> owner(static_cast<std::size_t>(g.width()) * g.height(), -1);
  int i = 0;
  for (int z = 0; z < cells.z; ++z) {
    for (int y = 0; y < cells.y; ++y) {
      for (int x = 0; x < cells.x; ++x, ++i) {
        const glm::ivec2 t = g.addressOf(x, y, z);
        ASSERT_GE(t.x, 0);
        ASSERT_GE(t.y, 0);
        ASSERT_LT(t.x, g.width());
        ASSERT_LT(t.y, g.height());
        // Direct indexing back: the tile names z, the texel in it x and y.
        const int tileZ = (t.y / cells.y) * g.tilesX + t.x / cells.x;
        ASSERT_EQ(glm::ivec3(t.x % cells.x, t.y % cells.y, tileZ), glm::ivec3(x, y, z));
        int& o = owner[static_cast<std::size_t>(t.y) * g.width() + t.x];
        ASSERT_EQ(o, -1) << "texel " << t.x << "," << t.y << " holds two cells";
        o = i;
        // The shader's float maths gives the same texel, exactly.
        const glm::vec2 s =
            shaderPageTexel(glm::vec3(x, y, z), glm::vec3(cells), static_cast<float>(g.tilesX));
        ASSERT_EQ(s, glm::vec2(t)) << x << "," << y << "," << z;
      }
    }
  }
}

TEST(BricksPageTable, ACellGridThatNoTilingFitsIsRefused) {
  // 200 cells wide cannot fit 128 texels.
  EXPECT_EQ(layout::BricksLayout::pageTableGeometry({200, 4, 4}, 128).tilesX, 0);
  // 128^3 cells need 128 tiles of 128^2: 16 per row in 2048, 8 rows.
  const layout::MosaicLayout::Geometry g =
      layout::BricksLayout::pageTableGeometry({128, 128, 128}, 2048);
  EXPECT_EQ(g.width() * g.height(), 128 * 128 * 128);
  EXPECT_LE(std::max(g.width(), g.height()), 2048);
}

// ipad2 (ES 2, 2048^2) refused the virtual 8192^3 u16 volume: its page table
// as one column was 64 x 4096 texels even with 128^3 bricks. Tiled, 64^3
// bricks fit (128^3 cells in 2048 x 1024), and 4096^3 takes 32^3 bricks.
TEST(BricksPageTable, Ipad2PlansTheVirtual8192CubedVolumeWithATiledTable) {
  const gpu::DeviceLimits ipad2 = limitsOf("ipad2");
  const Volume huge = Volume::shapeOnly({8192, 8192, 8192}, ScalarType::U16);
  const layout::LayoutPlan p = layout::BricksLayout::planFor(huge, ipad2);
  ASSERT_TRUE(p.fits) << p.reason;
  EXPECT_NE(p.reason.find("as 64^3 bricks"), std::string::npos) << p.reason;
  const layout::PlannedTexture& pages = p.textures.back();
  EXPECT_EQ(pages.label, "brick page table");
  EXPECT_LE(std::max(pages.size.x, pages.size.y), 2048);
  EXPECT_EQ(pages.bytes, 4ull * 128 * 128 * 128);
  EXPECT_LE(p.totalBytes, ipad2.textureBudget);
  const Volume big = Volume::shapeOnly({4096, 4096, 4096}, ScalarType::U16);
  const layout::LayoutPlan q = layout::BricksLayout::planFor(big, ipad2);
  ASSERT_TRUE(q.fits) << q.reason;
  EXPECT_NE(q.reason.find("as 32^3 bricks"), std::string::npos) << q.reason;
  // A smaller limit on request (what the render tests use).
  layout::BricksOptions small;
  small.pageTableMaxSide = 100;
  small.brickSize = 64;
  const layout::LayoutPlan r = layout::BricksLayout::planFor(huge, ipad2, small);
  EXPECT_FALSE(r.fits);
  EXPECT_NE(r.reason.find("do not fit a 100x100 page table"), std::string::npos) << r.reason;
}

// `tessera plan` lists the walk's float pages (ES 3, R8/R16 atlas, isotropic
// pyramid, at most 64^3 cells) beside the page table, 16 bytes a texel, and
// counts them in the total; ES 2 and the two-byte atlas have none.
TEST(BricksPageTable, ThePlanListsTheWalkPages) {
  const Volume u16 = Volume::shapeOnly({512, 512, 512}, ScalarType::U16);
  const layout::LayoutPlan p = layout::BricksLayout::planFor(u16, limitsOf("webgl2"));
  ASSERT_TRUE(p.fits) << p.reason;
  ASSERT_GE(p.textures.size(), 3u);
  const layout::PlannedTexture& pages = p.textures[p.textures.size() - 2];
  const layout::PlannedTexture& walk = p.textures.back();
  EXPECT_EQ(pages.label, "brick page table");
  EXPECT_EQ(walk.label, "brick walk pages");
  EXPECT_EQ(walk.format, "RGBA32F");
  EXPECT_EQ(walk.size, pages.size);
  // 16^3 cells of 32: 16 tiles of 16 x 16 texels.
  EXPECT_EQ(pages.bytes, 4ull * 16 * 16 * 16);
  EXPECT_EQ(walk.bytes, 16ull * 16 * 16 * 16);
  std::uint64_t sum = 0;
  for (const layout::PlannedTexture& t : p.textures) sum += t.bytes;
  EXPECT_EQ(p.totalBytes, sum);
  const layout::LayoutPlan es2 = layout::BricksLayout::planFor(u16, limitsOf("ipad2"));
  ASSERT_TRUE(es2.fits) << es2.reason;
  EXPECT_EQ(es2.textures.back().label, "brick page table");
  layout::BricksOptions noWalk;
  noWalk.walk = false;
  EXPECT_EQ(layout::BricksLayout::planFor(u16, limitsOf("webgl2"), noWalk).textures.back().label,
            "brick page table");
}
