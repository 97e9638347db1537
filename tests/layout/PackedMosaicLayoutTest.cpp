// packed-mosaic layout, dense and overlapped packings: the CPU twin of the
// address maths and every stored copy of a voxel against direct indexing,
// and the GPU sampleVolume() against direct indexing, with slices spilling
// across channels, tiles and textures; trilinear interpolation across those
// seams against the reference and against texture3d, on ES 3 and ES 2
// contexts; the plans, including the paper's capacity figures and which
// packing Auto takes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "layout/LayoutFixtures.h"
#include "support/GpuTestContext.h"
#include "support/ProbePositions.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/gpu/Program.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/LayoutProbe.h"
#include "tessera/layout/PackedMosaicLayout.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/reference/ReferenceRaycaster.h"

using namespace tessera;
using layout::PackedMosaicLayout;
using Packing = PackedMosaicLayout::Packing;

namespace {

using test::probePositions;

constexpr Packing kPackings[] = {Packing::Dense, Packing::Overlapped};

const char* nameOf(Packing p) {
  return p == Packing::Overlapped ? "overlapped" : "dense";
}

// The tiles each packing needs, from the definitions: dense ceil(D / 4);
// overlapped ceil((D - 1) / 3), at least one.
int tilesFor(Packing p, int depth) {
  if (p == Packing::Dense) return (depth + 3) / 4;
  return std::max(1, (depth - 1 + 2) / 3);
}

// The slice channel c of tile g holds, from the definitions; -1: none.
int sliceIn(Packing p, int depth, int g, int c) {
  if (p == Packing::Dense) return 4 * g + c < depth ? 4 * g + c : -1;
  return std::min(3 * g + c, depth - 1);
}

using test::addressPattern;
using test::es2Context;
using test::worstTrilinearError;

// Layouts that spill slices across channels, tiles and textures: the max 2D
// size forces the number of textures, for each packing (0: more than the
// shader's 16 samplers).
struct Spill {
  glm::ivec3 dims;
  int max2D;  // 0: the context's
  int maxTextures;
  int expectDense;
  int expectOverlapped;
  int expect(Packing p) const { return p == Packing::Dense ? expectDense : expectOverlapped; }
};
const std::vector<Spill>& spills() {
  static const std::vector<Spill> all = {
      // One texture; dense: 8 tiles, the last holding 1 slice; overlapped:
      // 10 tiles, the last repeating slice 28 in B and A.
      {{37, 53, 29}, 0, 16, 1, 1},  {{37, 53, 29}, 80, 5, 4, 5},  // 2 tiles per texture
      {{37, 53, 37}, 120, 2, 2, 2},  // 6 tiles per texture: dense 6 + 4, overlapped 6 + 6
      {{5, 3, 6}, 5, 2, 2, 2},       // 1 tile per texture
      {{4, 4, 64}, 4, 16, 16, 0},    // every sampler of the shader's chain (dense)
      {{4, 4, 49}, 4, 16, 13, 16},   // every sampler of the chain (overlapped)
      {{6, 5, 1}, 0, 16, 1, 1},      // one slice: every channel of overlapped holds it
      {{7, 5, 2}, 0, 16, 1, 1},      // two slices: overlapped R, G, B, A = 0, 1, 1, 1
  };
  return all;
}

gpu::DeviceLimits limitsFor(const gpu::DeviceCaps& caps, const Spill& p) {
  gpu::DeviceLimits l = gpu::DeviceLimits::of(caps);
  if (p.max2D != 0) l.max2DTextureSize = p.max2D;
  return l;
}

}  // namespace

TEST(PackedMosaicLayout, CpuTwinMatchesDirectIndexForEveryVoxel) {
  struct Case {
    glm::ivec3 dims;
    int max2D;
  };
  for (const Packing packing : kPackings) {
    for (const Case& c :
         {Case{{37, 53, 29}, 4096}, Case{{37, 53, 29}, 80}, Case{{37, 53, 37}, 120},
          Case{{1, 1, 1}, 1}, Case{{5, 3, 6}, 5}, Case{{4, 4, 64}, 4}, Case{{4, 4, 49}, 4},
          Case{{7, 9, 30}, 21}, Case{{6, 5, 2}, 6}, Case{{6, 5, 4}, 6}, Case{{6, 5, 5}, 6},
          Case{{3, 2, 7}, 3}, Case{{3, 2, 8}, 3}}) {
      SCOPED_TRACE(std::string(nameOf(packing)) + " " + std::to_string(c.dims.x) + "x" +
                   std::to_string(c.dims.y) + "x" + std::to_string(c.dims.z) + " max2D " +
                   std::to_string(c.max2D));
      const Volume v = addressPattern(c.dims, ScalarType::U8);
      const PackedMosaicLayout::Geometry g =
          PackedMosaicLayout::geometryFor(c.dims, c.max2D, packing);
      ASSERT_EQ(g.packing, packing);
      ASSERT_GT(g.textures, 0);
      ASSERT_LE(g.width(), c.max2D);
      ASSERT_LE(g.height(), c.max2D);
      ASSERT_EQ(g.tiles(), tilesFor(packing, c.dims.z));
      ASSERT_GE(g.textures * g.tilesPerTexture(), g.tiles());
      ASSERT_LT((g.textures - 1) * g.tilesPerTexture(), g.tiles()) << "an empty texture";
      const auto images = PackedMosaicLayout::pack(v, g);
      ASSERT_EQ(images.size(), static_cast<std::size_t>(g.textures));
      const std::size_t texels = static_cast<std::size_t>(g.width()) * g.height();
      // Byte index of texel (x, y), channel ch of tile `tile`, placed by the
      // definition (row-major grid, T tiles per texture), not by the class.
      const auto byteOf = [&](int tile, int ch, int x, int y) {
        const int cell = tile % g.tilesPerTexture();
        const int tx = (cell % g.tilesX) * c.dims.x + x;
        const int ty = (cell / g.tilesX) * c.dims.y + y;
        return std::make_pair(tile / g.tilesPerTexture(),
                              (static_cast<std::size_t>(ty) * g.width() + tx) * 4 + ch);
      };

      // Every stored copy: channel ch of every tile holds the slice the
      // packing's definition says (dense: none past the last, stored 0),
      // and every byte no tile channel holds (unused tiles) is 0.
      std::vector<std::vector<int>> hits(images.size(), std::vector<int>(texels * 4, 0));
      std::vector<int> copies(static_cast<std::size_t>(c.dims.z), 0);
      for (int tile = 0; tile < g.tiles(); ++tile) {
        for (int ch = 0; ch < 4; ++ch) {
          const int z = sliceIn(packing, c.dims.z, tile, ch);
          ASSERT_EQ(g.sliceAt(tile, ch), z) << "tile " << tile << " channel " << ch;
          if (z >= 0) ++copies[static_cast<std::size_t>(z)];
          for (int y = 0; y < c.dims.y; ++y) {
            for (int x = 0; x < c.dims.x; ++x) {
              const auto [t, i] = byteOf(tile, ch, x, y);
              ASSERT_EQ(images[t][i], z < 0 ? 0.0 : v.valueAt(x, y, z))
                  << "tile " << tile << " channel " << ch << " texel " << x << "," << y;
              ++hits[t][i];
            }
          }
        }
      }
      for (std::size_t t = 0; t < images.size(); ++t) {
        for (std::size_t i = 0; i < texels * 4; ++i) {
          ASSERT_LE(hits[t][i], 1);
          if (hits[t][i] == 0) {
            ASSERT_EQ(images[t][i], 0) << "texture " << t << " byte " << i;
          }
        }
      }
      // Dense stores each slice once; overlapped each slice 3g (0 < g <
      // tiles) twice (A of tile g - 1, R of tile g), the last one to four
      // times, the others once.
      for (int z = 0; z < c.dims.z; ++z) {
        int expect = 1;
        if (packing == Packing::Overlapped) {
          if (z == c.dims.z - 1) {
            // Channels (z - 3L) .. 3 of the last tile L.
            expect = 4 - (z - 3 * (tilesFor(packing, c.dims.z) - 1));
          } else if (z > 0 && z % 3 == 0) {
            expect = 2;
          }
        }
        EXPECT_EQ(copies[static_cast<std::size_t>(z)], expect) << "slice " << z;
      }

      // The primary copy addressOf() gives: its byte holds the voxel, and
      // it is where the definition puts it (dense: tile z / 4, channel
      // z % 4; overlapped: tile min(z / 3, last), channel z - 3 * tile).
      for (int z = 0; z < c.dims.z; ++z) {
        const int stride = packing == Packing::Dense ? 4 : 3;
        const int tile = std::min(z / stride, g.tiles() - 1);
        for (int y = 0; y < c.dims.y; ++y) {
          for (int x = 0; x < c.dims.x; ++x) {
            const PackedMosaicLayout::TexelAddress a = g.addressOf(x, y, z);
            ASSERT_TRUE(a.texture >= 0 && a.texture < g.textures && a.channel >= 0 &&
                        a.channel < 4 && a.x >= 0 && a.x < g.width() && a.y >= 0 &&
                        a.y < g.height());
            const auto [t, i] = byteOf(tile, z - stride * tile, x, y);
            ASSERT_EQ(a.texture, t) << "voxel " << x << "," << y << "," << z;
            ASSERT_EQ((static_cast<std::size_t>(a.y) * g.width() + a.x) * 4 + a.channel, i)
                << "voxel " << x << "," << y << "," << z;
            ASSERT_EQ(images[t][i], v.valueAt(x, y, z)) << "voxel " << x << "," << y << "," << z;
          }
        }
      }

      // What the shaders read for the sample pair (z0, z0 + 1).
      int channelSeams = 0, textureSeams = 0;
      for (int z = 0; z + 1 < c.dims.z; ++z) {
        const int x = 2 % c.dims.x, y = 1 % c.dims.y;
        if (packing == Packing::Overlapped) {
          // One texel: tile z / 3, channels z - 3g and the next.
          const int tile = z / 3;
          ASSERT_LT(tile, g.tiles());
          const auto [t0, i0] = byteOf(tile, z - 3 * tile, x, y);
          const auto [t1, i1] = byteOf(tile, z - 3 * tile + 1, x, y);
          EXPECT_EQ(t1, t0);
          EXPECT_EQ(i1, i0 + 1);
          EXPECT_EQ(images[t0][i0], v.valueAt(x, y, z)) << "slice " << z;
          EXPECT_EQ(images[t1][i1], v.valueAt(x, y, z + 1)) << "slice " << z + 1;
        } else {
          // Dense: the next channel of the same texel, or channel 0 of the
          // same texel position in the next tile (maybe the next texture).
          const auto a = g.addressOf(x, y, z);
          const auto b = g.addressOf(x, y, z + 1);
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
      if (packing == Packing::Dense) {
        EXPECT_EQ(channelSeams, (c.dims.z - 1) / 4);
        EXPECT_EQ(textureSeams, g.textures - 1);
      }
    }
  }
}

TEST(PackedMosaicLayout, GeometryUsesTheFewestTexturesThenTheSmallest) {
  for (const Packing packing : kPackings) {
    for (const glm::ivec3 d : {glm::ivec3{37, 53, 29}, glm::ivec3{128, 128, 128},
                               glm::ivec3{181, 217, 181}, glm::ivec3{512, 512, 384}}) {
      for (int max2D : {256, 1024, 2048, 4096}) {
        const PackedMosaicLayout::Geometry g = PackedMosaicLayout::geometryFor(d, max2D, packing);
        if (d.x > max2D || d.y > max2D) {
          EXPECT_EQ(g.textures, 0);
          continue;
        }
        const int tiles = tilesFor(packing, d.z);
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
  // Auto is a request, not a geometry: taken as dense.
  EXPECT_EQ(PackedMosaicLayout::geometryFor({8, 8, 8}, 64, Packing::Auto).packing, Packing::Dense);
}

TEST(PackedMosaicLayout, SampleMatchesDirectIndexForEveryVoxel) {
  gpu::GlContext& c = test::gpuContext();
  for (const Packing packing : kPackings) {
    for (const Spill& p : spills()) {
      const gpu::DeviceLimits limits = limitsFor(c.caps(), p);
      if (p.expect(packing) == 0) {
        const Volume v = Volume::shapeOnly(p.dims, ScalarType::U8);
        EXPECT_FALSE(PackedMosaicLayout::planFor(v, limits, p.maxTextures, packing).fits);
        continue;
      }
      for (ScalarType type : {ScalarType::U8, ScalarType::U16}) {
        const Volume v = addressPattern(p.dims, type);
        auto layout = PackedMosaicLayout::create(v, limits, c.ledger(), p.maxTextures, packing);
        ASSERT_EQ(layout->packing(), packing);
        ASSERT_EQ(layout->textureUnits(), p.expect(packing));
        const auto positions = layout::LayoutProbe::voxelCentres(v.dims());
        const std::vector<float> stored = layout::LayoutProbe(c).sample(*layout, positions);
        const layout::ValueMapping m = layout->rawFromStored();
        // u8 exact; u16 rounded to 8 bits over the value range.
        const double tolerance =
            type == ScalarType::U8 ? 1e-3 : 0.501 * v.valueRange().width() / 255.0;
        for (std::size_t i = 0; i < positions.size(); ++i) {
          ASSERT_NEAR(m.scale * stored[i] + m.offset, v.valueAtIndex(i), tolerance)
              << nameOf(packing) << " " << scalarTypeName(type) << " " << p.dims.z << " slices, "
              << p.expect(packing) << " textures, voxel " << i;
        }
      }
    }
  }
}

TEST(PackedMosaicLayout, SampleMatchesDirectIndexForEveryVoxelOnGles2) {
  {
    auto es2 = es2Context();
    for (const Packing packing : kPackings) {
      for (const Spill& p : spills()) {
        if (p.expect(packing) == 0 || p.expect(packing) > es2->caps().maxTextureUnits) continue;
        const Volume v = addressPattern(p.dims, ScalarType::U8);
        gpu::DeviceLimits limits = limitsFor(es2->caps(), p);
        ASSERT_EQ(limits.api, gpu::ApiLevel::Gles2);
        limits.textureUnits = p.maxTextures;
        auto layout = PackedMosaicLayout::create(v, limits, es2->ledger(), p.maxTextures, packing);
        ASSERT_EQ(layout->packing(), packing);
        ASSERT_EQ(layout->textureUnits(), p.expect(packing));
        const auto positions = layout::LayoutProbe::voxelCentres(v.dims());
        const std::vector<float> stored = layout::LayoutProbe(*es2).sample(*layout, positions);
        const double tolerance = 255.0 * layout::LayoutProbe::kRgba8Error + 1e-3;
        for (std::size_t i = 0; i < positions.size(); ++i) {
          ASSERT_NEAR(255.0 * stored[i], v.valueAtIndex(i), tolerance)
              << nameOf(packing) << " " << p.dims.z << " slices, " << p.expect(packing)
              << " textures, voxel " << i;
        }
      }
    }
  }
  test::gpuContext();
}

TEST(PackedMosaicLayout, InterpolationAcrossSeamsMatchesReferenceTrilinear) {
  const Volume v = makeSheppLogan({24, 20, 23});
  const std::vector<glm::vec3> positions = probePositions(v.dims());
  // max 2D 50: 2x2 tiles per texture, 2 textures (dense: the seam between
  // them at z 15|16; overlapped: 8 tiles, the second texture from slice 12);
  // max 2D 30: one tile per texture, 6 textures dense, 8 overlapped.
  for (const Packing packing : kPackings) {
    for (int max2D : {50, 30}) {
      const int expect = max2D == 50 ? 2 : packing == Packing::Dense ? 6 : 8;
      {
        gpu::GlContext& c = test::gpuContext();
        gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
        limits.max2DTextureSize = max2D;
        auto layout = PackedMosaicLayout::create(v, limits, c.ledger(), 8, packing);
        ASSERT_EQ(layout->textureUnits(), expect);
        const double worst = worstTrilinearError(v, *layout, positions,
                                                 layout::LayoutProbe(c).sample(*layout, positions));
        // Bilinear fetches with 8-bit weights (llvmpipe) and an exact z mix
        // (Texture3DLayoutTest explains the bound).
        EXPECT_LE(worst, 3.0) << nameOf(packing);
        std::printf(
            "  [measured] gles3, %s, %d textures: worst |GPU - CPU trilinear| = %.3f of "
            "255\n",
            nameOf(packing), layout->textureUnits(), worst);
      }
      {
        auto es2 = es2Context();
        gpu::DeviceLimits limits = gpu::DeviceLimits::of(es2->caps());
        limits.max2DTextureSize = max2D;
        limits.textureUnits = 8;
        auto layout = PackedMosaicLayout::create(v, limits, es2->ledger(), 8, packing);
        ASSERT_EQ(layout->textureUnits(), expect);
        const double worst = worstTrilinearError(
            v, *layout, positions, layout::LayoutProbe(*es2).sample(*layout, positions));
        EXPECT_LE(worst, 3.0) << nameOf(packing);
        std::printf(
            "  [measured] gles2, %s, %d textures: worst |GPU - CPU trilinear| = %.3f of "
            "255\n",
            nameOf(packing), layout->textureUnits(), worst);
      }
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
  const std::vector<glm::vec3> positions = probePositions(v.dims());
  layout::LayoutProbe probe(c);
  const std::vector<float> b = probe.sample(*texture3d, positions);
  for (const Packing packing : kPackings) {
    auto packed = PackedMosaicLayout::create(v, limits, c.ledger(), 8, packing);
    const std::vector<float> a = probe.sample(*packed, positions);
    double worst = 0.0;
    for (std::size_t i = 0; i < positions.size(); ++i) {
      worst = std::max(worst, 255.0 * std::abs(static_cast<double>(a[i]) - b[i]));
    }
    EXPECT_LE(worst, 3.0) << nameOf(packing);
    std::printf("  [measured] %s: worst |packed-mosaic - texture3d| = %.3f of 255\n",
                nameOf(packing), worst);
  }
}

// The packing reaches the shader as a define on line 2, which keeps the
// file's line numbers (compile errors point at packed_mosaic.glsl's lines).
TEST(PackedMosaicLayout, GlslDefinesThePackingWithoutMovingLines) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = addressPattern({5, 3, 6}, ScalarType::U8);
  gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  limits.max2DTextureSize = 5;
  const std::string file = gpu::embeddedShaderPart("layout/packed_mosaic.glsl").text;
  for (const Packing packing : kPackings) {
    auto layout = PackedMosaicLayout::create(v, limits, c.ledger(), 2, packing);
    const std::string text = layout->glsl().text;
    EXPECT_EQ(text.rfind("#define TESSERA_PACKED_TEXTURES 2\n#define TESSERA_PACKED_OVERLAPPED " +
                             std::string(packing == Packing::Overlapped ? "1" : "0") + "\n",
                         0),
              0u)
        << text.substr(0, 120);
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'),
              std::count(file.begin(), file.end(), '\n'));
  }
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
  // Dense: overlapped (128 tiles of 16 per texture) would need 8.
  EXPECT_NE(p.reason.find("packed-mosaic dense"), std::string::npos) << p.reason;
  EXPECT_NE(p.reason.find("dense: overlapped would need 8 textures instead of 6"),
            std::string::npos)
      << p.reason;
  const layout::LayoutPlan forced =
      PackedMosaicLayout::planFor(ct384, ipad2, 6, Packing::Overlapped);
  EXPECT_FALSE(forced.fits);
  EXPECT_NE(forced.reason.find("needs 8 texture units, 6 left"), std::string::npos)
      << forced.reason;
  // With the units, overlapped would fit, but dense stays: it needs fewer.
  EXPECT_NE(PackedMosaicLayout::planFor(ct384, ipad2, 8)
                .reason.find("dense: overlapped would need 8 textures instead of 6"),
            std::string::npos);
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
  // 341 overlapped tiles of 256 per texture: 2 textures (fit units and
  // budget, but a second unit for a third more memory is not taken).
  EXPECT_NE(w.reason.find("dense: overlapped would need 2 textures instead of 1"),
            std::string::npos)
      << w.reason;
}

TEST(PackedMosaicLayout, AutoTakesOverlappedWhereItFitsAndSaysWhy) {
  gpu::GlContext& c = test::gpuContext();
  gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  limits.max2DTextureSize = 120;
  limits.textureBudget = 0;
  // 37x53x37: 10 dense or 12 overlapped tiles, 6 per texture, 2 textures
  // either way.
  const Volume v = addressPattern({37, 53, 37}, ScalarType::U8);
  const layout::LayoutPlan plan = PackedMosaicLayout::planFor(v, limits, 4);
  ASSERT_TRUE(plan.fits) << plan.reason;
  EXPECT_NE(plan.reason.find("packed-mosaic overlapped"), std::string::npos) << plan.reason;
  EXPECT_NE(plan.reason.find("overlapped: one fetch per sample"), std::string::npos) << plan.reason;
  auto layout = PackedMosaicLayout::create(v, limits, c.ledger(), 4);
  EXPECT_EQ(layout->packing(), Packing::Overlapped);
  EXPECT_EQ(layout->textureUnits(), 2);
  EXPECT_EQ(layout->textureBytes(), plan.totalBytes);
  // Forced dense, for tests and benchmarks.
  const layout::LayoutPlan dense = PackedMosaicLayout::planFor(v, limits, 4, Packing::Dense);
  ASSERT_TRUE(dense.fits);
  EXPECT_NE(dense.reason.find("dense (as asked)"), std::string::npos) << dense.reason;
  EXPECT_EQ(PackedMosaicLayout::create(v, limits, c.ledger(), 4, Packing::Dense)->packing(),
            Packing::Dense);

  // Units: overlapped needs more textures than dense -> dense, and why.
  const Volume deep = addressPattern({37, 53, 29}, ScalarType::U8);
  gpu::DeviceLimits narrow = limits;
  narrow.max2DTextureSize = 80;  // 2 tiles per texture: dense 4 textures, overlapped 5
  const layout::LayoutPlan p4 = PackedMosaicLayout::planFor(deep, narrow, 16);
  ASSERT_TRUE(p4.fits) << p4.reason;
  EXPECT_EQ(p4.textures.size(), 4u);
  EXPECT_NE(p4.reason.find("dense: overlapped would need 5 textures instead of 4"),
            std::string::npos)
      << p4.reason;
  EXPECT_EQ(PackedMosaicLayout::create(deep, narrow, c.ledger(), 16)->packing(), Packing::Dense);

  // Budget: the same one texture, but overlapped's is larger; a budget
  // that holds only dense's -> dense, and why.
  gpu::DeviceLimits wide = limits;
  wide.max2DTextureSize = 4096;
  const layout::LayoutPlan d1 = PackedMosaicLayout::planFor(deep, wide, 1, Packing::Dense);
  const layout::LayoutPlan o1 = PackedMosaicLayout::planFor(deep, wide, 1, Packing::Overlapped);
  ASSERT_TRUE(d1.fits && o1.fits);
  ASSERT_EQ(d1.textures.size(), 1u);
  ASSERT_EQ(o1.textures.size(), 1u);
  ASSERT_GT(o1.totalBytes, d1.totalBytes);
  EXPECT_NE(PackedMosaicLayout::planFor(deep, wide, 1).reason.find("overlapped: one fetch"),
            std::string::npos);
  wide.textureBudget = o1.totalBytes - 1;
  const layout::LayoutPlan tight = PackedMosaicLayout::planFor(deep, wide, 1);
  ASSERT_TRUE(tight.fits) << tight.reason;
  EXPECT_EQ(tight.totalBytes, d1.totalBytes);
  EXPECT_NE(tight.reason.find("dense: overlapped ("), std::string::npos) << tight.reason;
  EXPECT_NE(tight.reason.find("would exceed the texture budget"), std::string::npos)
      << tight.reason;
  EXPECT_FALSE(PackedMosaicLayout::planFor(deep, wide, 1, Packing::Overlapped).fits);
  EXPECT_THROW(PackedMosaicLayout::create(deep, wide, c.ledger(), 1, Packing::Overlapped),
               GpuError);

  // Nothing fits: the refusal is dense's (overlapped needs at least as much).
  const layout::LayoutPlan none = PackedMosaicLayout::planFor(deep, narrow, 3);
  EXPECT_FALSE(none.fits);
  EXPECT_NE(none.reason.find("packed-mosaic dense"), std::string::npos) << none.reason;
  EXPECT_NE(none.reason.find("needs 4 texture units, 3 left"), std::string::npos) << none.reason;

  // Ch2 on an iPad 2: 60 overlapped tiles of 99 per 2048^2 texture, one
  // texture either way -> overlapped.
  gpu::DeviceLimits ipad2;
  ipad2.profile = "ipad2";
  ipad2.api = gpu::ApiLevel::Gles2;
  ipad2.max2DTextureSize = 2048;
  ipad2.textureUnits = 8;
  ipad2.textureBudget = 128ull << 20;
  const layout::LayoutPlan ch2 =
      PackedMosaicLayout::planFor(Volume::shapeOnly({181, 217, 181}, ScalarType::U8), ipad2, 6);
  ASSERT_TRUE(ch2.fits) << ch2.reason;
  EXPECT_EQ(ch2.textures.size(), 1u);
  EXPECT_NE(ch2.reason.find("overlapped: one fetch per sample"), std::string::npos) << ch2.reason;
}

// One to five slices: overlapped's repeated last slice (channels past D - 1)
// and z0 kept to [0, D - 2] are what a sample above the last slice centre
// reads; clamp-to-edge in z like the reference.
TEST(PackedMosaicLayout, ThinVolumesClampToEdgeInZ) {
  gpu::GlContext& c = test::gpuContext();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  for (const Packing packing : kPackings) {
    for (int depth = 1; depth <= 5; ++depth) {
      const Volume v = makeSheppLogan({24, 20, depth});
      auto layout = PackedMosaicLayout::create(v, limits, c.ledger(), 1, packing);
      const std::vector<glm::vec3> positions = probePositions(v.dims());
      const double worst = worstTrilinearError(v, *layout, positions,
                                               layout::LayoutProbe(c).sample(*layout, positions));
      EXPECT_LE(worst, 3.0) << nameOf(packing) << ", " << depth << " slices";
    }
  }
}
