// The brick walk (render/raycast.frag.glsl with LAYOUT_BRICK_WALK): the ray
// caster reads the bricks' page once per brick cell its ray enters and
// samples that brick directly. Its images must be those of the per-sample
// page lookup (BricksOptions::walk false), of the in-core layout and of the
// CPU reference: composite and MIP (transparent cells return their
// constant), shaded (the gradient's neighbours outside the block), clipped,
// on ES 3 (R8 and the two-byte RG8 atlas) and ES 2 (mosaic atlas). And the
// bricks' value blocks are the in-core layout's, so the walk skips exactly
// what in-core skips.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>

#include "support/BricksTestSupport.h"
#include "support/EachApi.h"
#include "support/GpuTestContext.h"
#include "support/TestCameras.h"
#include "support/TestTransferFunctions.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/BricksLayout.h"
#include "tessera/layout/MosaicLayout.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/layout/ValueBlocks.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/Raycaster.h"

using namespace tessera;

namespace {

constexpr int kImage = 96;

layout::BricksOptions levelZero(int b, bool walk = true) {
  return test::levelZeroBricks(b, walk);
}

void refine(layout::BricksLayout& bricks, const Camera& cam, const TransferFunction& tf) {
  test::refineBricks(bricks, cam, tf, kImage);
}

// Shepp-Logan widened to u16 with a ramp along x (the low byte varies).
std::shared_ptr<Volume> wide(const Volume& u8) {
  auto v = std::make_shared<Volume>(Volume::allocate(u8.dims(), ScalarType::U16));
  v->setSpacing(u8.spacing());
  for (std::size_t i = 0; i < u8.voxelCount(); ++i) {
    v->setValueAtIndex(i, u8.valueAtIndex(i) * 257.0 + static_cast<double>(i % 200));
  }
  v->invalidateRange();
  return v;
}

struct Case {
  const char* name;
  RenderSettings settings;
};

std::vector<Case> cases() {
  std::vector<Case> out;
  out.push_back({"composite", RenderSettings()});
  RenderSettings mip;
  mip.mode = RenderMode::Mip;
  out.push_back({"MIP", mip});
  RenderSettings shaded;
  shaded.shading.enabled = true;
  out.push_back({"shaded", shaded});
  RenderSettings clipped;
  clipped.clipping.cropMin = glm::dvec3(0.1, 0.2, 0.0);
  clipped.clipping.cropMax = glm::dvec3(0.9, 0.7, 0.85);
  out.push_back({"cropped", clipped});
  return out;
}

Image draw(gpu::GlContext& c, const Volume& v, const layout::Layout& layout, const Camera& cam,
           const RenderSettings& settings) {
  render::Raycaster caster(c, v, layout);
  caster.setSkipBlockSize(8);
  caster.setTransferFunction(test::visibleTf());
  return caster.render(cam, settings, kImage, kImage);
}

// Walked bricks of 12 (not a multiple of the 8^3 empty-space blocks: cells
// and blocks cross) and of 16, against the same bricks with a page lookup
// per sample, the in-core layout and the reference.
void compare(gpu::ApiLevel api, const std::shared_ptr<Volume>& v, bool noNorm16) {
  test::ApiContext context(api);
  gpu::GlContext& c = context.get();
  gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  if (noNorm16) limits.norm16Textures = false;
  for (const int b : {12, 16}) {
    auto walked = layout::BricksLayout::create(std::make_shared<lod::InCoreMultiresSource>(v, 8),
                                               limits, c.ledger(), levelZero(b));
    auto looked = layout::BricksLayout::create(std::make_shared<lod::InCoreMultiresSource>(v, 8),
                                               limits, c.ledger(), levelZero(b, false));
    EXPECT_TRUE(walked->walksBricks());
    EXPECT_FALSE(looked->walksBricks());
    std::unique_ptr<layout::Layout> inCore;
    if (api == gpu::ApiLevel::Gles3) {
      inCore = layout::Texture3DLayout::create(*v, limits, c.ledger());
    } else {
      inCore = layout::MosaicLayout::create(*v, limits, c.ledger());
    }
    const std::string what = std::string(api == gpu::ApiLevel::Gles3 ? "ES3 " : "ES2 ") +
                             std::string(scalarTypeName(v->type())) + (noNorm16 ? " RG8" : "") +
                             " B=" + std::to_string(b);
    for (const auto& [az, el] : {std::pair{35.0, 25.0}, std::pair{-120.0, -40.0}}) {
      const Camera cam = test::orbitCamera(v->extent(), az, el);
      refine(*walked, cam, test::visibleTf());
      refine(*looked, cam, test::visibleTf());
      for (const Case& k : cases()) {
        const Image w = draw(c, *v, *walked, cam, k.settings);
        const Image l = draw(c, *v, *looked, cam, k.settings);
        const Image i = draw(c, *v, *inCore, cam, k.settings);
        const Image ref = renderReference(*v, test::visibleTf(), cam, k.settings, kImage, kImage);
        const double vsLookup = psnr(w, l), vsInCore = psnr(w, i), vsRef = psnr(w, ref);
        const double lookupVsRef = psnr(l, ref);
        // The same samples as the per-sample lookup, up to the float maths of
        // the slot address.
        EXPECT_GE(vsLookup, 60.0) << what << " " << k.name << " az " << az;
        // As close to the reference as the per-sample lookup is (its own
        // distance to the reference is the ray caster's, not the walk's).
        EXPECT_GE(vsRef, std::min(lookupVsRef, 60.0) - 1.0)
            << what << " " << k.name << " az " << az;
        std::printf(
            "  [measured] %s %s az %g: walked vs per-sample lookup %.2f dB, vs %s %.2f dB, vs "
            "reference %.2f dB (lookup vs reference %.2f dB)\n",
            what.c_str(), k.name, az, vsLookup, inCore->name().c_str(), vsInCore, vsRef,
            lookupVsRef);
      }
    }
  }
}

}  // namespace

using BrickWalkOnEachApi = test::EachApi;
INSTANTIATE_TEST_SUITE_P(Api, BrickWalkOnEachApi, test::kEveryApi, test::apiParamName);

TEST_P(BrickWalkOnEachApi, WalkedImagesEqualThePerSampleLookupInCoreAndReference) {
  compare(GetParam(), std::make_shared<Volume>(makeSheppLogan({37, 53, 29})), false);
}

TEST_P(BrickWalkOnEachApi, SixteenBitBricksWalkToo) {
  compare(GetParam(), wide(makeSheppLogan({37, 53, 29})), false);
}

TEST(BrickWalk, TwoByteAtlasWalksToo) {
  compare(gpu::ApiLevel::Gles3, wide(makeSheppLogan({37, 53, 29})), true);
}

// Level-0 bricks give each 8^3 block the range an in-core layout gives it
// (ValueBlocks with the one-voxel support), also in the partial bricks at
// the far faces, and a block in a cell the page marks transparent exactly
// the constant that cell returns: the walk skips and steps as in core.
TEST(BrickWalk, LevelZeroBricksHoldTheInCoreValueBlocks) {
  gpu::GlContext& c = test::gpuContext();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  for (const glm::ivec3 dims : {glm::ivec3(37, 53, 29), glm::ivec3(45, 50, 37)}) {
    for (const bool sixteen : {false, true}) {
      auto u8 = std::make_shared<Volume>(makeSheppLogan(dims));
      const std::shared_ptr<Volume> v = sixteen ? wide(*u8) : u8;
      auto bricks = layout::BricksLayout::create(std::make_shared<lod::InCoreMultiresSource>(v, 8),
                                                 limits, c.ledger(), levelZero(16));
      refine(*bricks, test::orbitCamera(v->extent(), 30, 20), test::visibleTf());
      const layout::ValueBlocks direct(*v, 8, 1);
      const layout::ValueBlocks got = bricks->valueBlocks(8);
      ASSERT_EQ(got.mins().size(), direct.mins().size());
      const glm::ivec3 count = direct.blockCount();
      const layout::ValueMapping m = bricks->rawFromStored();
      std::size_t resident = 0, constant = 0, i = 0;
      for (int z = 0; z < count.z; ++z) {
        for (int y = 0; y < count.y; ++y) {
          for (int x = 0; x < count.x; ++x, ++i) {
            const auto at = bricks->lookup(glm::dvec3(x, y, z) * 8.0 + 4.0);
            if (at.level == 0) {
              EXPECT_EQ(got.mins()[i], direct.mins()[i]) << x << "," << y << "," << z;
              EXPECT_EQ(got.maxs()[i], direct.maxs()[i]) << x << "," << y << "," << z;
              ++resident;
            } else {
              ASSERT_EQ(at.level, -1) << "every cell at level 0 or transparent";
              const double top = sixteen ? 65535.0 : 255.0;  // stored units
              const auto value = static_cast<float>(m.offset + m.scale * at.texel.x / top);
              EXPECT_FLOAT_EQ(got.mins()[i], value);
              EXPECT_FLOAT_EQ(got.maxs()[i], value);
              ++constant;
            }
          }
        }
      }
      EXPECT_GT(resident, 0u);
      EXPECT_GT(constant, 0u);
      std::printf(
          "  [measured] %dx%dx%d %s: %zu blocks in level-0 bricks, %zu in transparent cells\n",
          dims.x, dims.y, dims.z, std::string(scalarTypeName(v->type())).c_str(), resident,
          constant);
    }
  }
}

// The walk's float pages (bricks.glsl BRICKS_WALK_PAGES) are a texture like
// the page table: the ledger, textureBytes() and the plan all count them,
// 16 bytes per page-table texel.
TEST(BrickWalk, WalkPagesAreCountedInTheLedgerAndListedInThePlan) {
  gpu::GlContext& c = test::gpuContext();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  if (limits.api != gpu::ApiLevel::Gles3) GTEST_SKIP() << "float walk pages are ES 3 only";
  auto v = std::make_shared<Volume>(makeSheppLogan({37, 53, 29}));
  for (const bool walk : {true, false}) {
    const std::uint64_t before = c.ledger().totalBytes();
    auto bricks = layout::BricksLayout::create(std::make_shared<lod::InCoreMultiresSource>(v, 8),
                                               limits, c.ledger(), levelZero(16, walk));
    const std::uint64_t ledgerBytes = c.ledger().totalBytes() - before;
    const layout::LayoutPlan& plan = bricks->plan();
    const layout::PlannedTexture* pages = nullptr;
    const layout::PlannedTexture* walkPages = nullptr;
    for (const layout::PlannedTexture& t : plan.textures) {
      if (t.label == "brick page table") pages = &t;
      if (t.label == "brick walk pages") walkPages = &t;
    }
    ASSERT_NE(pages, nullptr);
    // 3 x 4 x 2 cells of 16: two tiles of 3 x 4 texels.
    EXPECT_EQ(pages->bytes, 4u * 24u);
    if (walk) {
      ASSERT_NE(walkPages, nullptr);
      EXPECT_EQ(walkPages->format, "RGBA32F");
      EXPECT_EQ(walkPages->size, pages->size);
      EXPECT_EQ(walkPages->bytes, 16u * 24u);
    } else {
      EXPECT_EQ(walkPages, nullptr);
    }
    EXPECT_EQ(bricks->textureBytes(), ledgerBytes);
    EXPECT_EQ(bricks->textureBytes(), plan.totalBytes);
    EXPECT_EQ(bricks->textureUnits(), walk ? 3 : 2);
  }
}
