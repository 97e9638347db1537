// The planner: which layout, which sizes, and that it never gives up.
#include <gtest/gtest.h>

#include "tessera/core/Error.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/layout/BricksLayout.h"
#include "tessera/layout/LayoutRegistry.h"
#include "tessera/layout/Planner.h"

using namespace tessera;

namespace {

// Caps of a generous context of the profile's level, so that the profile's
// own limits are the ones that bind (as on the devices they describe).
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

layout::Plan plan(glm::ivec3 dims, const std::string& profile, const std::string& layout = "auto",
                  ScalarType type = ScalarType::U8) {
  layout::PlanRequest r;
  r.layout = layout;
  r.reservedUnits = 2;
  return layout::planLayout(Volume::shapeOnly(dims, type), limitsOf(profile), r);
}

}  // namespace

TEST(Planner, PrefersTexture3dWhereItFits) {
  const layout::Plan p = plan({181, 217, 181}, "webgl2");
  EXPECT_EQ(p.layout.layout, "texture3d");
  EXPECT_FALSE(p.downsampled());
  EXPECT_EQ(p.layout.totalBytes, 181u * 217 * 181);
}

TEST(Planner, Ch2OnIpad2IsOnePackedRgbaTexture) {
  // 2048^2 holds 11 x 9 = 99 tiles of 181 x 217: too few for 181 slices in
  // one channel, enough in four.
  const layout::Plan p = plan({181, 217, 181}, "ipad2");
  EXPECT_EQ(p.layout.layout, "packed-mosaic");
  EXPECT_FALSE(p.downsampled());
  ASSERT_EQ(p.layout.textures.size(), 1u);
  ASSERT_EQ(p.rejected.size(), 2u);
  EXPECT_EQ(p.rejected[0].layout, "texture3d");
  EXPECT_EQ(p.rejected[1].layout, "mosaic");
  EXPECT_FALSE(p.reason.empty());
}

TEST(Planner, PaperCapacityIpad2Holds512x512x384WithoutDownsampling) {
  // Noguera & Jiménez 2012: six RGBA 2048^2 textures (8 units minus the TF
  // and the technique's).
  const layout::Plan p = plan({512, 512, 384}, "ipad2");
  EXPECT_EQ(p.layout.layout, "packed-mosaic");
  EXPECT_FALSE(p.downsampled());
  EXPECT_EQ(p.layout.textures.size(), 6u);
  for (const auto& t : p.layout.textures) EXPECT_LE(std::max(t.size.x, t.size.y), 2048);
}

TEST(Planner, PaperCapacityWebgl1Holds512x512x1024InOne8192Texture) {
  const layout::Plan p = plan({512, 512, 1024}, "webgl1-desktop-2012");
  EXPECT_EQ(p.layout.layout, "packed-mosaic");
  EXPECT_FALSE(p.downsampled());
  ASSERT_EQ(p.layout.textures.size(), 1u);
  EXPECT_EQ(p.layout.textures[0].size.x, 8192);
  EXPECT_EQ(p.layout.textures[0].size.y, 8192);
  EXPECT_EQ(p.layout.totalBytes, 8192u * 8192 * 4);
}

TEST(Planner, DownsamplesOnlyWhenNothingFitsAndSaysSo) {
  const layout::Plan p = plan({512, 512, 512}, "ipad2");  // 6 textures hold 384 slices
  EXPECT_TRUE(p.downsampled());
  EXPECT_TRUE(p.layout.fits);
  EXPECT_NE(p.reason.find("downsampled"), std::string::npos) << p.reason;
  // Halving one axis is enough; the plan must not throw away more.
  EXPECT_EQ(p.downsample.x * p.downsample.y * p.downsample.z, 2);
  EXPECT_EQ(p.volumeDims, (glm::ivec3(512, 512, 512) + p.downsample - 1) / p.downsample);
}

TEST(Planner, AxesLongerThanTheTextureAreHalved) {
  const layout::Plan p = plan({4000, 64, 16}, "ipad2");  // a tile wider than 2048
  EXPECT_TRUE(p.downsampled());
  EXPECT_GE(p.downsample.x, 2);
  EXPECT_LE(p.volumeDims.x, 2048);
}

TEST(Planner, EveryBuiltinProfileGetsAPlanWithinItsBudget) {
  for (const gpu::DeviceProfile& profile : gpu::DeviceProfile::builtins()) {
    for (glm::ivec3 dims : {glm::ivec3(181, 217, 181), glm::ivec3(512, 512, 384),
                            glm::ivec3(37, 53, 29), glm::ivec3(1024, 1024, 600)}) {
      const gpu::DeviceLimits limits = limitsOf(profile.name);
      layout::PlanRequest r;
      r.reservedUnits = std::min(2, limits.textureUnits - 1);
      const layout::Plan p = layout::planLayout(Volume::shapeOnly(dims, ScalarType::U8), limits, r);
      EXPECT_TRUE(p.layout.fits) << profile.name;
      if (limits.textureBudget) {
        EXPECT_LE(p.layout.totalBytes, limits.textureBudget) << profile.name;
      }
      EXPECT_LE(static_cast<int>(p.layout.textures.size()), p.volumeUnits) << profile.name;
    }
  }
}

TEST(Planner, ImpossibleWishesAreClearErrors) {
  EXPECT_THROW(plan({64, 64, 64}, "ipad2", "texture3d"), InputError);
  EXPECT_THROW(plan({64, 64, 64}, "webgl2", "no-such-layout"), InputError);
  EXPECT_EQ(plan({64, 64, 64}, "webgl2", "bricks").layout.layout, "bricks");
  const layout::Plan forced = plan({64, 64, 64}, "webgl2", "packed-mosaic");
  EXPECT_EQ(forced.layout.layout, "packed-mosaic");
  const layout::Plan mosaic = plan({64, 64, 64}, "webgl2", "mosaic");
  EXPECT_EQ(mosaic.layout.layout, "mosaic");
}

namespace {

// Restores the global registry after a test registered layouts of its own.
struct KeepLayoutRegistry {
  layout::LayoutRegistry saved = layout::LayoutRegistry::global();
  ~KeepLayoutRegistry() { layout::LayoutRegistry::global() = saved; }
};

// A stand-in for a layout that keeps only a 64x64 window of the volume
// resident (as a bricked layout would): it fits anywhere with one unit.
layout::LayoutEntry residentWindowLayout(bool needs3DTextures = false) {
  const std::string name = needs3DTextures ? "test-window-3d" : "test-window";
  return {.name = name,
          .needs3DTextures = needs3DTextures,
          .plan =
              [name](const Volume& shape, const gpu::DeviceLimits& limits, int units) {
                layout::LayoutPlan p;
                p.layout = name;
                p.textures.push_back({"window", {64, 64, 1}, false, "R8", 64 * 64});
                p.totalBytes = 64 * 64;
                p.fits = units >= 1 && limits.max2DTextureSize >= 64;
                p.reason = "a 64x64 window of " + std::to_string(shape.dims().x) + " columns";
                return p;
              },
          .create = [](const Volume&, const gpu::DeviceLimits&, gpu::MemoryLedger&, int)
              -> std::unique_ptr<layout::Layout> { throw Error("not uploaded in this test"); }};
}

}  // namespace

TEST(Planner, ChoosesFromTheRegisteredLayoutsInOrder) {
  EXPECT_EQ(layout::LayoutRegistry::global().names(),
            (std::vector<std::string>{"texture3d", "mosaic", "packed-mosaic", "bricks", "fcc",
                                      "fcc-half"}));
  EXPECT_EQ(layout::LayoutRegistry::global().choices(),
            "auto, texture3d, mosaic, packed-mosaic, bricks, fcc or fcc-half");
}

TEST(Planner, ALayoutRegisteredLaterIsPlannedByName) {
  const KeepLayoutRegistry keep;
  layout::LayoutRegistry::global().add(residentWindowLayout());
  const layout::Plan p = plan({181, 217, 181}, "ipad2", "test-window");
  EXPECT_EQ(p.layout.layout, "test-window");
  EXPECT_EQ(p.layout.totalBytes, 64u * 64);
  try {
    plan({64, 64, 64}, "webgl2", "no-such-layout");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("test-window"), std::string::npos) << e.what();
  }
}

TEST(Planner, AutoTriesARegisteredLayoutBeforeDownsampling) {
  // 4000 columns: no built-in layout holds it on ipad2 (a tile wider than
  // 2048); the registered one does, so nothing is thrown away.
  const KeepLayoutRegistry keep;
  layout::LayoutRegistry::global().add(residentWindowLayout());
  const layout::Plan p = plan({4000, 64, 16}, "ipad2");
  EXPECT_EQ(p.layout.layout, "test-window");
  EXPECT_FALSE(p.downsampled());
  ASSERT_EQ(p.rejected.size(), 3u);
  EXPECT_NE(p.reason.find("not packed-mosaic"), std::string::npos) << p.reason;
}

TEST(Planner, ARegisteredLayoutsNeedsAreChecked) {
  const KeepLayoutRegistry keep;
  layout::LayoutRegistry::global().add(residentWindowLayout());
  layout::LayoutRegistry::global().add(residentWindowLayout(true));
  try {
    plan({64, 64, 64}, "ipad2", "test-window-3d");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "layout test-window-3d needs 3D textures, which ipad2 does not have (use mosaic, "
              "packed-mosaic, bricks or test-window)");
  }
  EXPECT_EQ(plan({64, 64, 64}, "webgl2", "test-window-3d").layout.layout, "test-window-3d");
}

namespace {

layout::Plan planStreamed(glm::ivec3 dims, const std::string& profile) {
  layout::PlanRequest r;
  r.streamed = true;
  return layout::planLayout(Volume::shapeOnly(dims, ScalarType::U8), limitsOf(profile), r);
}

}  // namespace

TEST(Planner, StreamedVolumesThatFitNoInCoreLayoutAreBrickedAndItSaysWhy) {
  // 1024^3 u8 = 1 GiB: over shield-k1's texture budget (and its 469 MB host).
  const layout::Plan big = planStreamed({1024, 1024, 1024}, "shield-k1");
  EXPECT_EQ(big.layout.layout, "bricks");
  EXPECT_FALSE(big.downsampled());
  EXPECT_NE(big.reason.find("not texture3d"), std::string::npos) << big.reason;
  EXPECT_LE(big.layout.totalBytes, limitsOf("shield-k1").textureBudget);
  // The paper's dog head fits the SHIELD in core (Schultz 2016 §8.2)...
  EXPECT_EQ(planStreamed({512, 512, 894}, "shield-k1").layout.layout, "texture3d");
  // ...not the iPad 2: packed-mosaic would need 14 textures (units) of 2048^2.
  const layout::Plan ipad = planStreamed({512, 512, 894}, "ipad2");
  EXPECT_EQ(ipad.layout.layout, "bricks") << ipad.reason;
  EXPECT_LE(ipad.layout.totalBytes, limitsOf("ipad2").textureBudget);
  // A streamed volume over the host budget is not read in core even where
  // the textures would hold it: 800^3 = 488 MiB on shield-k1 (469 MiB host).
  const layout::Plan host = planStreamed({800, 800, 800}, "shield-k1");
  EXPECT_EQ(host.layout.layout, "bricks");
  EXPECT_NE(host.reason.find("host memory"), std::string::npos) << host.reason;
  // In-core volumes keep downsampling (their front ends do not stream).
  EXPECT_TRUE(plan({512, 512, 512}, "ipad2").downsampled());
}

// The bricks atlas counts against the host budget too (on llvmpipe and on
// unified-memory GPUs it is process memory): it leaves room for the host's
// fixed overhead and a brick cache, and shrinks when that room is short.
TEST(Planner, BricksAtlasLeavesTheHostBudgetRoomForItsCache) {
  const Volume shape = Volume::shapeOnly({1024, 1024, 1024}, ScalarType::U8);
  gpu::DeviceLimits limits = limitsOf("shield-k1");  // 1 GiB textures, 469 MB host
  const std::uint64_t k1 = layout::BricksLayout::planFor(shape, limits).totalBytes;
  EXPECT_LE(k1, limits.hostBudget - (176ull + 32ull) * (1ull << 20));
  EXPECT_GT(k1, 200ull << 20);  // the 255 MiB atlas still fits beside it
  // A 300 MiB host: the atlas shrinks to what is left, and still fits.
  limits.hostBudget = 300ull << 20;
  const layout::LayoutPlan small = layout::BricksLayout::planFor(shape, limits);
  EXPECT_TRUE(small.fits) << small.reason;
  EXPECT_LE(small.totalBytes, (300ull - 176 - 32) << 20);
  EXPECT_LT(small.totalBytes, k1);
  // No host budget: the texture budget and the 256 MiB cap alone.
  limits.hostBudget = 0;
  EXPECT_GE(layout::BricksLayout::planFor(shape, limits).totalBytes, k1);
}

// A single-level store: its one level is also its coarsest, pinned in the
// atlas; it fits when the atlas holds all of it (before, the planner refused
// "holds no more than the 1 coarsest bricks" with 256 MiB to spare), and
// is refused when it does not.
TEST(Planner, ASingleLevelSourceFitsWhenTheAtlasHoldsAllOfIt) {
  const Volume shape = Volume::shapeOnly({64, 64, 64}, ScalarType::U8);
  layout::BricksOptions options;
  options.brickSize = 64;
  const gpu::DeviceLimits limits = limitsOf("shield-k1");
  const layout::LayoutPlan one =
      layout::BricksLayout::planFor(shape, limits, options, glm::ivec3(64), {{64, 64, 64}});
  EXPECT_TRUE(one.fits) << one.reason;
  EXPECT_NE(one.reason.find("1-brick"), std::string::npos) << one.reason;
  // 2x2x2 bricks of one level in a budget of less than eight slots.
  const Volume big = Volume::shapeOnly({128, 128, 128}, ScalarType::U8);
  options.atlasBytesCap = 5ull * 66 * 66 * 66;
  const layout::LayoutPlan refused =
      layout::BricksLayout::planFor(big, limits, options, glm::ivec3(64), {{128, 128, 128}});
  EXPECT_FALSE(refused.fits);
  EXPECT_NE(refused.reason.find("coarsest bricks"), std::string::npos) << refused.reason;
}
