// mosaic layout: the CPU twin of the address maths and the GPU sampleVolume()
// against direct indexing, trilinear interpolation against the reference and
// against texture3d, on ES 3 and ES 2 contexts, and the plans.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "layout/LayoutFixtures.h"
#include "support/GpuTestContext.h"
#include "support/ProbePositions.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/LayoutProbe.h"
#include "tessera/layout/MosaicLayout.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/reference/ReferenceRaycaster.h"

using namespace tessera;
using layout::MosaicLayout;

namespace {

using test::addressPattern;
using test::es2Context;
using test::probePositions;
using test::worstTrilinearError;

gpu::DeviceLimits limitsWithMax2D(const gpu::DeviceCaps& caps, int max2D) {
  gpu::DeviceLimits l = gpu::DeviceLimits::of(caps);
  l.max2DTextureSize = max2D;
  return l;
}

}  // namespace

TEST(MosaicLayout, CpuTwinMatchesDirectIndexForEveryVoxel) {
  struct Case {
    glm::ivec3 dims;
    int max2D;
  };
  for (const Case& c : {Case{{37, 53, 29}, 4096}, Case{{37, 53, 29}, 265}, Case{{1, 1, 1}, 1},
                        Case{{5, 3, 2}, 6}, Case{{16, 16, 7}, 64}, Case{{3, 200, 9}, 200}}) {
    const Volume v = addressPattern(c.dims, ScalarType::U8);
    const MosaicLayout::Geometry g = MosaicLayout::geometryFor(c.dims, c.max2D);
    ASSERT_GT(g.tilesX, 0) << c.dims.x << "x" << c.dims.y << "x" << c.dims.z;
    ASSERT_LE(g.width(), c.max2D);
    ASSERT_LE(g.height(), c.max2D);
    const std::vector<std::uint8_t> image = MosaicLayout::pack(v, g, MosaicLayout::Storage::R8);
    ASSERT_EQ(image.size(), static_cast<std::size_t>(g.width()) * g.height());
    std::vector<int> hits(image.size(), 0);
    for (int z = 0; z < c.dims.z; ++z) {
      for (int y = 0; y < c.dims.y; ++y) {
        for (int x = 0; x < c.dims.x; ++x) {
          const glm::ivec2 a = g.addressOf(x, y, z);
          ASSERT_TRUE(a.x >= 0 && a.x < g.width() && a.y >= 0 && a.y < g.height());
          const std::size_t t = static_cast<std::size_t>(a.y) * g.width() + a.x;
          ASSERT_EQ(image[t], v.valueAt(x, y, z)) << "voxel " << x << "," << y << "," << z;
          ++hits[t];
        }
      }
    }
    // One voxel per texel; the texels of the unused tiles are 0.
    for (std::size_t t = 0; t < image.size(); ++t) {
      ASSERT_LE(hits[t], 1);
      if (hits[t] == 0) {
        ASSERT_EQ(image[t], 0);
      }
    }
  }
}

TEST(MosaicLayout, PackingNormalisesOtherTypesOverTheValueRange) {
  const Volume v = addressPattern({9, 7, 5}, ScalarType::I16);
  const ValueRange r = v.valueRange();
  const MosaicLayout::Geometry g = MosaicLayout::geometryFor(v.dims(), 64);
  const std::vector<std::uint8_t> r16 = MosaicLayout::pack(v, g, MosaicLayout::Storage::R16);
  const std::vector<std::uint8_t> l8 = MosaicLayout::pack(v, g, MosaicLayout::Storage::Luminance8);
  for (int z = 0; z < 5; ++z) {
    for (int y = 0; y < 7; ++y) {
      for (int x = 0; x < 9; ++x) {
        const glm::ivec2 a = g.addressOf(x, y, z);
        const std::size_t t = static_cast<std::size_t>(a.y) * g.width() + a.x;
        const double n = (v.valueAt(x, y, z) - r.min) / r.width();
        std::uint16_t q16 = 0;
        std::memcpy(&q16, r16.data() + 2 * t, 2);
        EXPECT_EQ(q16, std::lround(n * 65535.0));
        EXPECT_EQ(l8[t], std::lround(n * 255.0));
      }
    }
  }
}

TEST(MosaicLayout, GridIsTheSmallestThatHoldsTheSlices) {
  for (const glm::ivec3 d : {glm::ivec3{37, 53, 29}, glm::ivec3{128, 128, 128},
                             glm::ivec3{181, 217, 181}, glm::ivec3{64, 32, 100}}) {
    for (int max2D : {256, 1024, 2048, 4096}) {
      const MosaicLayout::Geometry g = MosaicLayout::geometryFor(d, max2D);
      std::uint64_t bestArea = 0;
      for (int tx = 1; tx <= max2D / d.x; ++tx) {
        for (int ty = 1; ty <= max2D / d.y; ++ty) {
          if (tx * ty < d.z) continue;
          const std::uint64_t area = static_cast<std::uint64_t>(tx * d.x) * (ty * d.y);
          if (bestArea == 0 || area < bestArea) bestArea = area;
        }
      }
      if (bestArea == 0) {
        EXPECT_EQ(g.tilesX, 0) << "no grid fits, yet one was chosen";
        continue;
      }
      ASSERT_GT(g.tilesX, 0);
      EXPECT_GE(g.tilesX * g.tilesY, d.z);
      EXPECT_LE(g.width(), max2D);
      EXPECT_LE(g.height(), max2D);
      EXPECT_EQ(static_cast<std::uint64_t>(g.width()) * g.height(), bestArea);
    }
  }
  // Least area first: a prime number of slices makes a strip (29 x 1 tiles)
  // where it fits; among grids of equal area the squarest wins.
  EXPECT_EQ(MosaicLayout::geometryFor({37, 53, 29}, 4096).tilesX, 29);
  const MosaicLayout::Geometry g = MosaicLayout::geometryFor({37, 53, 29}, 265);
  EXPECT_EQ(glm::ivec2(g.tilesX, g.tilesY), glm::ivec2(6, 5));
  const MosaicLayout::Geometry s = MosaicLayout::geometryFor({40, 30, 20}, 4096);
  EXPECT_EQ(glm::ivec2(s.tilesX, s.tilesY), glm::ivec2(4, 5));  // 160x150, not 200x120
}

TEST(MosaicLayout, SampleMatchesDirectIndexForEveryVoxel) {
  gpu::GlContext& c = test::gpuContext();
  // The context's max 2D size gives a 29x1 strip; 265 a 6x5 grid.
  for (int max2D : {0, 265}) {
    for (ScalarType type : {ScalarType::U8, ScalarType::U16, ScalarType::I16, ScalarType::F32}) {
      const Volume v = addressPattern({37, 53, 29}, type);
      gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
      if (max2D != 0) limits.max2DTextureSize = max2D;
      auto layout = MosaicLayout::create(v, limits, c.ledger());
      const auto positions = layout::LayoutProbe::voxelCentres(v.dims());
      const std::vector<float> stored = layout::LayoutProbe(c).sample(*layout, positions);
      const layout::ValueMapping m = layout->rawFromStored();
      const ValueRange r = v.valueRange();
      // u8 is stored exactly, and 8-bit formats filter with 8-bit weights,
      // which the float rounding of a voxel centre's texture coordinate
      // cannot move off 0. 16-bit storage is exact to half a quantum, but
      // llvmpipe filters it with finer weights, and that rounding (up to
      // about size * 2^-23 texels, larger in a mosaic than in a 3D texture)
      // weighs in the neighbour, which in this pattern can differ by the
      // whole range.
      const int size = std::max(layout->geometry().width(), layout->geometry().height());
      const double tolerance =
          type == ScalarType::U8
              ? 1e-3
              : 0.51 * r.width() / 65535.0 + std::ldexp(static_cast<double>(size), -22) * r.width();
      for (std::size_t i = 0; i < positions.size(); ++i) {
        ASSERT_NEAR(m.scale * stored[i] + m.offset, v.valueAtIndex(i), tolerance)
            << "type " << scalarTypeName(type) << " voxel " << i << " mosaic "
            << layout->geometry().width() << "x" << layout->geometry().height();
      }
    }
  }
}

TEST(MosaicLayout, SampleMatchesDirectIndexForEveryVoxelOnGles2) {
  {
    auto es2 = es2Context();
    for (ScalarType type : {ScalarType::U8, ScalarType::U16}) {
      const Volume v = addressPattern({37, 53, 29}, type);
      const gpu::DeviceLimits limits = gpu::DeviceLimits::of(es2->caps());
      ASSERT_EQ(limits.api, gpu::ApiLevel::Gles2);
      auto layout = MosaicLayout::create(v, limits, es2->ledger());
      EXPECT_EQ(layout->storage(), MosaicLayout::Storage::Luminance8);
      const auto positions = layout::LayoutProbe::voxelCentres(v.dims());
      const std::vector<float> stored = layout::LayoutProbe(*es2).sample(*layout, positions);
      const layout::ValueMapping m = layout->rawFromStored();
      const ValueRange r = v.valueRange();
      // u8 exact; other types are rounded to 8 bits on ES 2; plus the
      // probe's RGBA8 encoding.
      const double tolerance = m.scale * layout::LayoutProbe::kRgba8Error +
                               (type == ScalarType::U8 ? 1e-3 : 0.501 * r.width() / 255.0);
      for (std::size_t i = 0; i < positions.size(); ++i) {
        ASSERT_NEAR(m.scale * stored[i] + m.offset, v.valueAtIndex(i), tolerance)
            << "type " << scalarTypeName(type) << " voxel " << i;
      }
    }
  }
  test::gpuContext();
}

TEST(MosaicLayout, InterpolationMatchesReferenceTrilinearOnGles3AndGles2) {
  const Volume v = makeSheppLogan({24, 20, 23});
  const std::vector<glm::vec3> positions = probePositions(v.dims());
  {
    gpu::GlContext& c = test::gpuContext();
    auto layout = MosaicLayout::create(v, limitsWithMax2D(c.caps(), 130), c.ledger());
    // 4x6 tiles: tile borders in x and y.
    ASSERT_EQ(glm::ivec2(layout->geometry().tilesX, layout->geometry().tilesY), glm::ivec2(4, 6));
    const double worst = worstTrilinearError(v, *layout, positions,
                                             layout::LayoutProbe(c).sample(*layout, positions));
    // Two bilinear fetches with 8-bit weights (llvmpipe) and an exact z mix:
    // at most one weight quantum per fetch axis on a step of at most 255
    // (Texture3DLayoutTest explains the bound).
    EXPECT_LE(worst, 3.0);
    std::printf("  [measured] gles3: worst |GPU - CPU trilinear| = %.3f of 255\n", worst);
  }
  {
    auto es2 = es2Context();
    auto layout = MosaicLayout::create(v, limitsWithMax2D(es2->caps(), 130), es2->ledger());
    const double worst = worstTrilinearError(v, *layout, positions,
                                             layout::LayoutProbe(*es2).sample(*layout, positions));
    EXPECT_LE(worst, 3.0);
    std::printf("  [measured] gles2: worst |GPU - CPU trilinear| = %.3f of 255\n", worst);
  }
  test::gpuContext();
}

TEST(MosaicLayout, AgreesWithTexture3D) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSheppLogan({24, 20, 23});
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  auto mosaic = MosaicLayout::create(v, limitsWithMax2D(c.caps(), 130), c.ledger());
  auto texture3d = layout::Texture3DLayout::create(v, limits, c.ledger());
  const std::vector<glm::vec3> positions = probePositions(v.dims());
  layout::LayoutProbe probe(c);
  const std::vector<float> a = probe.sample(*mosaic, positions);
  const std::vector<float> b = probe.sample(*texture3d, positions);
  double worst = 0.0;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    worst = std::max(worst, 255.0 * std::abs(static_cast<double>(a[i]) - b[i]));
  }
  EXPECT_LE(worst, 3.0);
  std::printf("  [measured] worst |mosaic - texture3d| = %.3f of 255\n", worst);
}

TEST(MosaicLayout, PlanReportsBytesAndRefusesWhatDoesNotFit) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSphere({40, 30, 20});
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  const layout::LayoutPlan plan = MosaicLayout::planFor(v, limits);
  ASSERT_TRUE(plan.fits) << plan.reason;
  EXPECT_EQ(plan.layout, "mosaic");
  ASSERT_EQ(plan.textures.size(), 1u);
  EXPECT_EQ(plan.textures[0].format, "R8");
  // 20 slices of 40x30: 4x5 tiles = 160x150 texels.
  EXPECT_EQ(plan.textures[0].size, glm::ivec3(160, 150, 1));
  EXPECT_EQ(plan.totalBytes, 160u * 150u);
  EXPECT_NE(plan.reason.find("160x150"), std::string::npos) << plan.reason;
  auto layout = MosaicLayout::create(v, limits, c.ledger());
  EXPECT_EQ(layout->textureBytes(), plan.totalBytes);
  EXPECT_EQ(layout->textureUnits(), 1);
  EXPECT_EQ(layout->volumeDims(), v.dims());

  gpu::DeviceLimits small = limits;
  small.max2DTextureSize = 32;  // a 40x30 slice does not fit at all
  EXPECT_FALSE(MosaicLayout::planFor(v, small).fits);
  EXPECT_NE(MosaicLayout::planFor(v, small).reason.find("exceeds the max 2D texture size 32"),
            std::string::npos);
  EXPECT_THROW(MosaicLayout::create(v, small, c.ledger()), GpuError);
  small.max2DTextureSize = 100;  // 2x3 tiles < 20 slices
  EXPECT_FALSE(MosaicLayout::planFor(v, small).fits);
  EXPECT_NE(MosaicLayout::planFor(v, small).reason.find("20 slices"), std::string::npos);
  gpu::DeviceLimits tight = limits;
  tight.textureBudget = 160 * 150 - 1;
  EXPECT_FALSE(MosaicLayout::planFor(v, tight).fits);
  EXPECT_NE(MosaicLayout::planFor(v, tight).reason.find("budget"), std::string::npos);
  gpu::DeviceLimits noUnits = limits;
  noUnits.textureUnits = 0;
  EXPECT_FALSE(MosaicLayout::planFor(v, noUnits).fits);

  // Other types: 16 bits on ES 3, 8 bits on ES 2.
  const Volume v16 = Volume::shapeOnly({40, 30, 20}, ScalarType::U16);
  gpu::DeviceLimits es3 = limits;
  es3.norm16Textures = true;
  EXPECT_EQ(MosaicLayout::planFor(v16, es3).textures[0].format, "R16");
  es3.norm16Textures = false;
  EXPECT_EQ(MosaicLayout::planFor(v16, es3).textures[0].format, "R16F");
  EXPECT_EQ(MosaicLayout::planFor(v16, es3).totalBytes, 2u * 160 * 150);
  gpu::DeviceLimits es2 = limits;
  es2.api = gpu::ApiLevel::Gles2;
  const layout::LayoutPlan p2 = MosaicLayout::planFor(v16, es2);
  EXPECT_EQ(p2.textures[0].format, "L8");
  EXPECT_EQ(p2.totalBytes, 160u * 150);
  EXPECT_NE(p2.reason.find("quantised to 8 bits"), std::string::npos);

  // The paper's point: 512x512x384 u8 does not fit one 8192^2 mosaic (256 tiles).
  const Volume big = Volume::shapeOnly({512, 512, 384}, ScalarType::U8);
  gpu::DeviceLimits webgl = limits;
  webgl.max2DTextureSize = 8192;
  EXPECT_FALSE(MosaicLayout::planFor(big, webgl).fits);
}
