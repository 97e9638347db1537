// packed-mosaic layout: the CPU twin of the address maths and the GPU
// sampleVolume() against direct indexing, with slices spilling across
// channels, tiles and textures; trilinear interpolation across those seams
// against the reference and against texture3d, on ES 3 and ES 2 contexts;
// the plans, including the paper's capacity figures.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "support/GpuTestContext.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/LayoutProbe.h"
#include "tessera/layout/PackedMosaicLayout.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/reference/ReferenceRaycaster.h"

using namespace tessera;
using layout::PackedMosaicLayout;

namespace {

// A volume whose every voxel differs from its neighbours, so an addressing
// slip of one voxel along any axis shows.
Volume addressPattern(glm::ivec3 d, ScalarType type) {
  Volume v = Volume::allocate(d, type);
  for (int z = 0; z < d.z; ++z) {
    for (int y = 0; y < d.y; ++y) {
      for (int x = 0; x < d.x; ++x) {
        const double u8 = (x * 7 + y * 31 + z * 101) % 256;
        v.setValueAtIndex(v.index(x, y, z), type == ScalarType::U8 ? u8 : u8 * 200.0 + x);
      }
    }
  }
  return v;
}

std::unique_ptr<gpu::GlContext> es2Context() {
  gpu::GlContext::Options options;
  options.api = gpu::ApiLevel::Gles2;
  return gpu::GlContext::createHeadless(options);
}

// Layouts that spill slices across channels, tiles and textures: the max 2D
// size forces the number of textures.
struct Packing {
  glm::ivec3 dims;
  int max2D;  // 0: the context's
  int maxTextures;
  int expectTextures;
};
const std::vector<Packing>& packings() {
  static const std::vector<Packing> all = {
      {{37, 53, 29}, 0, 16, 1},   // one texture, 8 tiles, the last holding 1 slice
      {{37, 53, 29}, 80, 4, 4},   // 2 tiles per texture, 4 textures
      {{37, 53, 37}, 120, 2, 2},  // 6 + 4 tiles: the last texture partly empty
      {{5, 3, 6}, 5, 2, 2},       // 1 tile per texture, the second half full
      {{4, 4, 64}, 4, 16, 16},    // every sampler of the shader's chain
  };
  return all;
}

gpu::DeviceLimits limitsFor(const gpu::DeviceCaps& caps, const Packing& p) {
  gpu::DeviceLimits l = gpu::DeviceLimits::of(caps);
  if (p.max2D != 0) l.max2DTextureSize = p.max2D;
  return l;
}

// A deterministic scatter over the whole box, plus positions at the tile
// borders in x and y (edge texel centres, just inside and outside them, the
// box faces) and, in z, between every pair of slices that straddles a
// channel-3 -> channel-0 seam (the next tile, possibly in the next texture).
std::vector<glm::vec3> probePositions(glm::ivec3 d) {
  std::vector<glm::vec3> p;
  for (int i = 0; i < 4000; ++i) {
    p.emplace_back(std::fmod(i * 0.6180339887f, 1.0f), std::fmod(i * 0.7548776662f, 1.0f),
                   std::fmod(i * 0.5698402910f, 1.0f));
  }
  const auto edges = [](int n) {
    const float t = 1.0f / static_cast<float>(n);
    return std::vector<float>{0.0f,
                              0.25f * t,
                              0.5f * t,
                              0.5f * t + 1e-4f,
                              0.75f * t,
                              1.0f - 0.75f * t,
                              1.0f - 0.5f * t - 1e-4f,
                              1.0f - 0.5f * t,
                              1.0f - 0.25f * t,
                              1.0f};
  };
  int k = 0;
  for (float x : edges(d.x)) {
    for (float y : edges(d.y)) {
      const float z = std::fmod(0.37f + 0.2357f * static_cast<float>(k++), 1.0f);
      p.emplace_back(x, y, z);
    }
  }
  for (float z : edges(d.z)) {
    for (int i = 0; i < 20; ++i) p.emplace_back(0.05f * i, 1.0f - 0.05f * i, z);
  }
  for (int s = 3; s + 1 < d.z; s += 4) {
    for (float f : {0.0f, 0.1f, 0.3f, 0.5f, 0.7f, 0.9f, 1.0f}) {
      const float z = (static_cast<float>(s) + 0.5f + f) / static_cast<float>(d.z);
      for (int i = 0; i < 12; ++i) {
        p.emplace_back(std::fmod(0.03f + i * 0.4142f, 1.0f), std::fmod(0.07f + i * 0.7321f, 1.0f),
                       z);
      }
    }
  }
  return p;
}

double worstTrilinearError(const Volume& v, const layout::Layout& l,
                           const std::vector<glm::vec3>& positions,
                           const std::vector<float>& stored) {
  const layout::ValueMapping m = l.rawFromStored();
  double worst = 0.0;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const double gpu = m.scale * stored[i] + m.offset;
    worst = std::max(worst, std::abs(gpu - sampleTrilinear(v, glm::dvec3(positions[i]))));
  }
  return worst;
}

}  // namespace

TEST(PackedMosaicLayout, CpuTwinMatchesDirectIndexForEveryVoxel) {
  struct Case {
    glm::ivec3 dims;
    int max2D;
  };
  for (const Case& c :
       {Case{{37, 53, 29}, 4096}, Case{{37, 53, 29}, 80}, Case{{37, 53, 37}, 120},
        Case{{1, 1, 1}, 1}, Case{{5, 3, 6}, 5}, Case{{4, 4, 64}, 4}, Case{{7, 9, 30}, 21}}) {
    const Volume v = addressPattern(c.dims, ScalarType::U8);
    const PackedMosaicLayout::Geometry g = PackedMosaicLayout::geometryFor(c.dims, c.max2D);
    ASSERT_GT(g.textures, 0);
    ASSERT_LE(g.width(), c.max2D);
    ASSERT_LE(g.height(), c.max2D);
    ASSERT_GE(g.textures * g.tilesPerTexture(), g.tiles());
    const auto images = PackedMosaicLayout::pack(v, g);
    ASSERT_EQ(images.size(), static_cast<std::size_t>(g.textures));
    const std::size_t texels = static_cast<std::size_t>(g.width()) * g.height();
    std::vector<std::vector<int>> hits(images.size(), std::vector<int>(texels * 4, 0));
    int channelSeams = 0, textureSeams = 0;
    for (int z = 0; z < c.dims.z; ++z) {
      for (int y = 0; y < c.dims.y; ++y) {
        for (int x = 0; x < c.dims.x; ++x) {
          const PackedMosaicLayout::TexelAddress a = g.addressOf(x, y, z);
          ASSERT_TRUE(a.texture >= 0 && a.texture < g.textures && a.channel >= 0 && a.channel < 4 &&
                      a.x >= 0 && a.x < g.width() && a.y >= 0 && a.y < g.height());
          const std::size_t i = (static_cast<std::size_t>(a.y) * g.width() + a.x) * 4 + a.channel;
          ASSERT_EQ(images[a.texture][i], v.valueAt(x, y, z))
              << "voxel " << x << "," << y << "," << z;
          ++hits[a.texture][i];
        }
      }
      // Neighbours in z: the next channel of the same texel, or channel 0 of
      // the same texel position in the next tile (maybe the next texture).
      if (z + 1 < c.dims.z) {
        const auto a = g.addressOf(2 % c.dims.x, 1 % c.dims.y, z);
        const auto b = g.addressOf(2 % c.dims.x, 1 % c.dims.y, z + 1);
        if (a.channel < 3) {
          EXPECT_EQ(b.channel, a.channel + 1);
          EXPECT_EQ(glm::ivec3(b.texture, b.x, b.y), glm::ivec3(a.texture, a.x, a.y));
        } else {
          EXPECT_EQ(b.channel, 0);
          ++channelSeams;
          if (b.texture != a.texture) ++textureSeams;
        }
      }
    }
    EXPECT_EQ(channelSeams, (c.dims.z - 1) / 4);
    EXPECT_EQ(textureSeams, g.textures - 1);
    // One voxel per channel of a texel; unused channels and tiles are 0.
    for (std::size_t t = 0; t < images.size(); ++t) {
      for (std::size_t i = 0; i < texels * 4; ++i) {
        ASSERT_LE(hits[t][i], 1);
        if (hits[t][i] == 0) {
          ASSERT_EQ(images[t][i], 0) << "texture " << t << " byte " << i;
        }
      }
    }
  }
}

TEST(PackedMosaicLayout, GeometryUsesTheFewestTexturesThenTheSmallest) {
  for (const glm::ivec3 d : {glm::ivec3{37, 53, 29}, glm::ivec3{128, 128, 128},
                             glm::ivec3{181, 217, 181}, glm::ivec3{512, 512, 384}}) {
    for (int max2D : {256, 1024, 2048, 4096}) {
      const PackedMosaicLayout::Geometry g = PackedMosaicLayout::geometryFor(d, max2D);
      if (d.x > max2D || d.y > max2D) {
        EXPECT_EQ(g.textures, 0);
        continue;
      }
      const int tiles = (d.z + 3) / 4;
      const int perTexture = (max2D / d.x) * (max2D / d.y);
      EXPECT_EQ(g.textures, (tiles + perTexture - 1) / perTexture);
      EXPECT_LE(g.width(), max2D);
      EXPECT_LE(g.height(), max2D);
      // The smallest grid that holds the tiles spread over those textures.
      const int each = (tiles + g.textures - 1) / g.textures;
      std::uint64_t bestArea = 0;
      for (int tx = 1; tx <= max2D / d.x; ++tx) {
        for (int ty = 1; ty <= max2D / d.y; ++ty) {
          const std::uint64_t area = static_cast<std::uint64_t>(tx * d.x) * (ty * d.y);
          if (tx * ty >= each && (bestArea == 0 || area < bestArea)) bestArea = area;
        }
      }
      EXPECT_EQ(static_cast<std::uint64_t>(g.width()) * g.height(), bestArea);
    }
  }
}

TEST(PackedMosaicLayout, SampleMatchesDirectIndexForEveryVoxel) {
  gpu::GlContext& c = test::gpuContext();
  for (const Packing& p : packings()) {
    for (ScalarType type : {ScalarType::U8, ScalarType::U16}) {
      const Volume v = addressPattern(p.dims, type);
      auto layout =
          PackedMosaicLayout::create(v, limitsFor(c.caps(), p), c.ledger(), p.maxTextures);
      ASSERT_EQ(layout->textureUnits(), p.expectTextures);
      const auto positions = layout::LayoutProbe::voxelCentres(v.dims());
      const std::vector<float> stored = layout::LayoutProbe(c).sample(*layout, positions);
      const layout::ValueMapping m = layout->rawFromStored();
      // u8 exact; u16 rounded to 8 bits over the value range.
      const double tolerance =
          type == ScalarType::U8 ? 1e-3 : 0.501 * v.valueRange().width() / 255.0;
      for (std::size_t i = 0; i < positions.size(); ++i) {
        ASSERT_NEAR(m.scale * stored[i] + m.offset, v.valueAtIndex(i), tolerance)
            << scalarTypeName(type) << " " << p.expectTextures << " textures, voxel " << i;
      }
    }
  }
}

TEST(PackedMosaicLayout, SampleMatchesDirectIndexForEveryVoxelOnGles2) {
  {
    auto es2 = es2Context();
    for (const Packing& p : packings()) {
      if (p.expectTextures > es2->caps().maxTextureUnits) continue;
      const Volume v = addressPattern(p.dims, ScalarType::U8);
      gpu::DeviceLimits limits = limitsFor(es2->caps(), p);
      ASSERT_EQ(limits.api, gpu::ApiLevel::Gles2);
      limits.textureUnits = p.maxTextures;
      auto layout = PackedMosaicLayout::create(v, limits, es2->ledger(), p.maxTextures);
      ASSERT_EQ(layout->textureUnits(), p.expectTextures);
      const auto positions = layout::LayoutProbe::voxelCentres(v.dims());
      const std::vector<float> stored = layout::LayoutProbe(*es2).sample(*layout, positions);
      const double tolerance = 255.0 * layout::LayoutProbe::kRgba8Error + 1e-3;
      for (std::size_t i = 0; i < positions.size(); ++i) {
        ASSERT_NEAR(255.0 * stored[i], v.valueAtIndex(i), tolerance)
            << p.expectTextures << " textures, voxel " << i;
      }
    }
  }
  test::gpuContext();
}

TEST(PackedMosaicLayout, InterpolationAcrossSeamsMatchesReferenceTrilinear) {
  const Volume v = makeSheppLogan({24, 20, 23});
  const std::vector<glm::vec3> positions = probePositions(v.dims());
  // max 2D 50: 2x2 tiles per texture, the seam between textures at z 15|16;
  // max 2D 30: one tile (4 slices) per texture, 6 textures.
  for (int max2D : {50, 30}) {
    {
      gpu::GlContext& c = test::gpuContext();
      gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
      limits.max2DTextureSize = max2D;
      auto layout = PackedMosaicLayout::create(v, limits, c.ledger(), 8);
      ASSERT_EQ(layout->textureUnits(), max2D == 50 ? 2 : 6);
      const double worst = worstTrilinearError(v, *layout, positions,
                                               layout::LayoutProbe(c).sample(*layout, positions));
      // Two bilinear fetches with 8-bit weights (llvmpipe) and an exact z
      // mix (Texture3DLayoutTest explains the bound).
      EXPECT_LE(worst, 3.0);
      std::printf("  [measured] gles3, %d textures: worst |GPU - CPU trilinear| = %.3f of 255\n",
                  layout->textureUnits(), worst);
    }
    {
      auto es2 = es2Context();
      gpu::DeviceLimits limits = gpu::DeviceLimits::of(es2->caps());
      limits.max2DTextureSize = max2D;
      limits.textureUnits = 8;
      auto layout = PackedMosaicLayout::create(v, limits, es2->ledger(), 8);
      const double worst = worstTrilinearError(
          v, *layout, positions, layout::LayoutProbe(*es2).sample(*layout, positions));
      EXPECT_LE(worst, 3.0);
      std::printf("  [measured] gles2, %d textures: worst |GPU - CPU trilinear| = %.3f of 255\n",
                  layout->textureUnits(), worst);
    }
  }
  test::gpuContext();
}

TEST(PackedMosaicLayout, AgreesWithTexture3D) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSheppLogan({24, 20, 23});
  gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  auto texture3d = layout::Texture3DLayout::create(v, limits, c.ledger());
  limits.max2DTextureSize = 50;
  auto packed = PackedMosaicLayout::create(v, limits, c.ledger(), 8);
  const std::vector<glm::vec3> positions = probePositions(v.dims());
  layout::LayoutProbe probe(c);
  const std::vector<float> a = probe.sample(*packed, positions);
  const std::vector<float> b = probe.sample(*texture3d, positions);
  double worst = 0.0;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    worst = std::max(worst, 255.0 * std::abs(static_cast<double>(a[i]) - b[i]));
  }
  EXPECT_LE(worst, 3.0);
  std::printf("  [measured] worst |packed-mosaic - texture3d| = %.3f of 255\n", worst);
}

TEST(PackedMosaicLayout, PlanReportsBytesAndRefusesWhatDoesNotFit) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = addressPattern({37, 53, 37}, ScalarType::U8);
  gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  limits.max2DTextureSize = 120;
  const layout::LayoutPlan plan = PackedMosaicLayout::planFor(v, limits, 4);
  ASSERT_TRUE(plan.fits) << plan.reason;
  EXPECT_EQ(plan.layout, "packed-mosaic");
  ASSERT_EQ(plan.textures.size(), 2u);
  for (const layout::PlannedTexture& t : plan.textures) {
    EXPECT_EQ(t.format, "RGBA8");
    EXPECT_EQ(t.size, glm::ivec3(111, 106, 1));  // 3x2 tiles of 37x53
  }
  EXPECT_EQ(plan.totalBytes, 2u * 111 * 106 * 4);
  EXPECT_NE(plan.reason.find("2 RGBA8 111x106 textures"), std::string::npos) << plan.reason;
  auto layout = PackedMosaicLayout::create(v, limits, c.ledger(), 4);
  EXPECT_EQ(layout->textureBytes(), plan.totalBytes);
  EXPECT_EQ(layout->textureUnits(), 2);
  EXPECT_EQ(layout->volumeDims(), v.dims());

  // Units: the caller's maxTextures and the device's.
  const layout::LayoutPlan one = PackedMosaicLayout::planFor(v, limits, 1);
  EXPECT_FALSE(one.fits);
  EXPECT_NE(one.reason.find("needs 2 texture units, 1 left"), std::string::npos) << one.reason;
  EXPECT_THROW(PackedMosaicLayout::create(v, limits, c.ledger(), 1), GpuError);
  gpu::DeviceLimits fewUnits = limits;
  fewUnits.textureUnits = 1;
  EXPECT_FALSE(PackedMosaicLayout::planFor(v, fewUnits, 4).fits);
  // Size: a slice larger than the max 2D texture size.
  gpu::DeviceLimits small = limits;
  small.max2DTextureSize = 50;
  EXPECT_FALSE(PackedMosaicLayout::planFor(v, small, 16).fits);
  EXPECT_NE(PackedMosaicLayout::planFor(v, small, 16).reason.find("exceeds the max 2D"),
            std::string::npos);
  // Budget.
  gpu::DeviceLimits tight = limits;
  tight.textureBudget = plan.totalBytes - 1;
  EXPECT_FALSE(PackedMosaicLayout::planFor(v, tight, 4).fits);
  EXPECT_NE(PackedMosaicLayout::planFor(v, tight, 4).reason.find("budget"), std::string::npos);
  // More textures than the shader's sampler chain.
  gpu::DeviceLimits tiny = limits;
  tiny.max2DTextureSize = 4;
  const Volume many = Volume::shapeOnly({4, 4, 68}, ScalarType::U8);
  EXPECT_FALSE(PackedMosaicLayout::planFor(many, tiny, 64).fits);
  // Other types are quantised to 8 bits, and say so.
  const Volume v16 = Volume::shapeOnly({37, 53, 37}, ScalarType::I16);
  const layout::LayoutPlan p16 = PackedMosaicLayout::planFor(v16, limits, 4);
  EXPECT_EQ(p16.totalBytes, plan.totalBytes);
  EXPECT_NE(p16.reason.find("quantised to 8 bits"), std::string::npos);
}

// Noguera & Jiménez 2012, section 4: 512x512x384 is what an iPad 2 holds
// (2048^2, 8 units, 2 kept for the transfer function and the technique), and
// 512x512x1024 fills all four channels of one 8192^2 texture (WebGL).
TEST(PackedMosaicLayout, PlansThePapersCapacities) {
  gpu::DeviceLimits ipad2;
  ipad2.profile = "ipad2";
  ipad2.api = gpu::ApiLevel::Gles2;
  ipad2.max2DTextureSize = 2048;
  ipad2.textureUnits = 8;
  const Volume ct384 = Volume::shapeOnly({512, 512, 384}, ScalarType::U8);
  const layout::LayoutPlan p = PackedMosaicLayout::planFor(ct384, ipad2, 6);
  ASSERT_TRUE(p.fits) << p.reason;
  ASSERT_EQ(p.textures.size(), 6u);
  for (const layout::PlannedTexture& t : p.textures) {
    EXPECT_EQ(t.size, glm::ivec3(2048, 2048, 1));
  }
  EXPECT_EQ(p.totalBytes, 6ull * 2048 * 2048 * 4);  // 96 MiB
  EXPECT_NE(p.reason.find("512x512x384 u8 in 6 RGBA8 2048x2048 textures"), std::string::npos)
      << p.reason;
  EXPECT_NE(p.reason.find("96 MiB"), std::string::npos) << p.reason;
  // One slice more needs a seventh texture, which the iPad 2 does not have.
  const layout::LayoutPlan p388 =
      PackedMosaicLayout::planFor(Volume::shapeOnly({512, 512, 388}, ScalarType::U8), ipad2, 6);
  EXPECT_FALSE(p388.fits);
  EXPECT_NE(p388.reason.find("needs 7 texture units, 6 left"), std::string::npos) << p388.reason;

  gpu::DeviceLimits webgl = ipad2;
  webgl.profile = "webgl1-desktop-2012";
  webgl.max2DTextureSize = 8192;
  webgl.textureUnits = 16;
  const Volume ct1024 = Volume::shapeOnly({512, 512, 1024}, ScalarType::U8);
  const layout::LayoutPlan w = PackedMosaicLayout::planFor(ct1024, webgl, 14);
  ASSERT_TRUE(w.fits) << w.reason;
  ASSERT_EQ(w.textures.size(), 1u);
  EXPECT_EQ(w.textures[0].size, glm::ivec3(8192, 8192, 1));
  EXPECT_EQ(w.totalBytes, 8192ull * 8192 * 4);  // 256 MiB
  EXPECT_NE(w.reason.find("in one RGBA8 8192x8192 texture"), std::string::npos) << w.reason;
}
