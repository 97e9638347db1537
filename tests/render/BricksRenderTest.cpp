// The bricks layout end to end: bricked renders equal the in-core
// texture3d/mosaic renders and the CPU reference (brick faces crossed by many
// rays, a brick size that does not divide the volume), on ES 3 (3D atlas)
// and ES 2 (mosaic atlas); the page table's address maths against direct
// indexing; coarse fallback without holes; a volume 4x the texture budget
// within the ledger; a source that fails for some bricks.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>

#include "support/EachApi.h"
#include "support/GpuTestContext.h"
#include "support/TestCameras.h"
#include "support/TestTransferFunctions.h"
#include "support/WrappedSources.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/DeviceSession.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/BricksLayout.h"
#include "tessera/layout/LayoutProbe.h"
#include "tessera/layout/MosaicLayout.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/lod/MultiresVolumeSource.h"
#include "tessera/lod/ProceduralMultiresSource.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/Raycaster.h"
#include "tessera/render/TechniqueRegistry.h"

using namespace tessera;
using test::visibleTf;

namespace {

constexpr int kImage = 96;

std::shared_ptr<const Volume> seamVolume() {
  return std::make_shared<const Volume>(makeSheppLogan({37, 53, 29}));
}

Camera viewOf(const Volume& v, double azimuth, double elevation) {
  return test::orbitCamera(v.extent(), azimuth, elevation);
}

// Streams until every brick the view wants is resident; returns the frames.
int refine(layout::BricksLayout& bricks, const Camera& cam, const TransferFunction& tf,
           layout::BricksFrame* last = nullptr) {
  for (int frame = 1; frame <= 400; ++frame) {
    const layout::BricksFrame f = bricks.update(cam, kImage, kImage, tf);
    if (last) *last = f;
    if (f.complete) return frame;
    if (f.uploaded == 0) bricks.waitForBricks(20.0);
  }
  ADD_FAILURE() << "bricks never completed";
  return -1;
}

Image renderWith(gpu::GlContext& c, const Volume& v, const layout::Layout& layout,
                 const Camera& cam, const RenderSettings& settings = {}) {
  render::Raycaster caster(c, v, layout);
  caster.setSkipBlockSize(8);
  caster.setTransferFunction(visibleTf());
  return caster.render(cam, settings, kImage, kImage);
}

layout::BricksOptions smallBricks(int b) {
  layout::BricksOptions o;
  o.brickSize = b;
  o.pixelsPerVoxel = 0.05;  // every brick at level 0 for these tiny volumes
  // Reads inline, in request order: which bricks a frame finds resident then
  // does not depend on how two reader threads were scheduled (under load one
  // cell once ended a refinement a level coarser). Threads: FlakySource test.
  o.workers = 0;
  return o;
}

void compareWithInCore(gpu::ApiLevel api) {
  test::ApiContext context(api);
  gpu::GlContext& c = context.get();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  const auto v = seamVolume();
  // B = 12: 37x53x29 is 4x5x3 bricks, the last ones partial. On ES 2,
  // 256^2 textures hold 23 slots each: the atlas spans several textures.
  gpu::DeviceLimits brickLimits = limits;
  if (api == gpu::ApiLevel::Gles2) brickLimits.max2DTextureSize = 256;
  auto bricks = layout::BricksLayout::create(std::make_shared<lod::InCoreMultiresSource>(v, 8),
                                             brickLimits, c.ledger(), smallBricks(12));
  if (api == gpu::ApiLevel::Gles2) {
    EXPECT_GE(bricks->textureUnits(), 4) << bricks->plan().reason;
  }
  std::unique_ptr<layout::Layout> inCore;
  if (api == gpu::ApiLevel::Gles3) {
    inCore = layout::Texture3DLayout::create(*v, limits, c.ledger());
  } else {
    inCore = layout::MosaicLayout::create(*v, limits, c.ledger());
  }
  // Oblique views: rays cross brick faces along all three axes.
  for (const auto& [az, el] : {std::pair{35.0, 25.0}, std::pair{-120.0, -40.0}}) {
    const Camera cam = viewOf(*v, az, el);
    layout::BricksFrame f;
    refine(*bricks, cam, visibleTf(), &f);
    EXPECT_EQ(f.cellsPerLevel[0] + f.cellsPerLevel.back(), 60) << "all at level 0 or empty";
    const Image viaBricks = renderWith(c, *v, *bricks, cam);
    const Image viaInCore = renderWith(c, *v, *inCore, cam);
    const Image ref = renderReference(*v, visibleTf(), cam, RenderSettings(), kImage, kImage);
    const double vsInCore = psnr(viaBricks, viaInCore);
    const double vsRef = psnr(viaBricks, ref);
    EXPECT_GE(vsInCore, 45.0);
    EXPECT_GE(vsRef, 40.0);
    std::printf("  [measured] %s az %g el %g: bricks vs %s %.2f dB, vs reference %.2f dB\n",
                api == gpu::ApiLevel::Gles2 ? "ES2 mosaic atlas" : "ES3 3D atlas", az, el,
                inCore->name().c_str(), vsInCore, vsRef);
  }
}

using test::FlakySource;

}  // namespace

using BricksRenderOnEachApi = test::EachApi;
INSTANTIATE_TEST_SUITE_P(Api, BricksRenderOnEachApi, test::kEveryApi, test::apiParamName);

// The in-core layout: texture3d on ES 3, mosaic on ES 2.
TEST_P(BricksRenderOnEachApi, MatchesInCoreLayoutAndReference) {
  compareWithInCore(GetParam());
}

// A page table of several tile rows (its side forced down to 10 texels: the
// 4x5x3 cells of 12^3 bricks as 2 x 2 tiles of 4 x 5) on ES 3 and ES 2:
// every voxel centre samples its own voxel, and the image is the reference's.
TEST_P(BricksRenderOnEachApi, PageTableOfSeveralTileRowsMatchesTheReference) {
  test::ApiContext context(GetParam());
  gpu::GlContext& c = context.get();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  const auto v = seamVolume();
  layout::BricksOptions o = smallBricks(12);
  o.pageTableMaxSide = 10;
  auto bricks = layout::BricksLayout::create(std::make_shared<lod::InCoreMultiresSource>(v, 8),
                                             limits, c.ledger(), o);
  const layout::MosaicLayout::Geometry& g = bricks->pageGeometry();
  ASSERT_EQ(g.dims, glm::ivec3(4, 5, 3));
  ASSERT_GE(g.tilesY, 2) << bricks->plan().reason;
  ASSERT_LE(std::max(g.width(), g.height()), 10);
  TransferFunction everything;  // every value visible: no transparent cells
  everything.addOpacity(0.0, 0.5);
  const Camera cam = viewOf(*v, 35, 25);
  refine(*bricks, cam, everything);
  layout::LayoutProbe probe(c);
  const std::vector<float> got =
      probe.sample(*bricks, layout::LayoutProbe::voxelCentres(v->dims()));
  ASSERT_EQ(got.size(), static_cast<std::size_t>(v->voxelCount()));
  for (std::size_t k = 0; k < got.size(); ++k) {
    ASSERT_NEAR(got[k] * 255.0, v->valueAtIndex(k), 1e-3) << k;
  }
  refine(*bricks, cam, visibleTf());
  const Image viaBricks = renderWith(c, *v, *bricks, cam);
  const Image ref = renderReference(*v, visibleTf(), cam, RenderSettings(), kImage, kImage);
  const double db = psnr(viaBricks, ref);
  EXPECT_GE(db, 45.0);
  std::printf("  [measured] %s, %dx%d page table of %d x %d tiles: bricks vs reference %.2f dB\n",
              GetParam() == gpu::ApiLevel::Gles2 ? "ES2" : "ES3", g.width(), g.height(), g.tilesX,
              g.tilesY, db);
}

TEST(BricksRender, PageTableLookupMatchesDirectIndexingForEveryVoxel) {
  gpu::GlContext& c = test::gpuContext();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  const auto v = seamVolume();
  auto bricks = layout::BricksLayout::create(std::make_shared<lod::InCoreMultiresSource>(v, 8),
                                             limits, c.ledger(), smallBricks(12));
  TransferFunction everything;  // every value visible: no transparent cells
  everything.addOpacity(0.0, 0.5);
  layout::BricksFrame f;
  refine(*bricks, viewOf(*v, 10, 10), everything, &f);
  EXPECT_FALSE(f.limitedByBudget);
  // CPU twin: every voxel centre maps to its own voxel in its brick's slot.
  const std::vector<glm::vec3> centres = layout::LayoutProbe::voxelCentres(v->dims());
  const glm::ivec3 d = v->dims();
  std::size_t i = 0;
  for (int z = 0; z < d.z; ++z)
    for (int y = 0; y < d.y; ++y)
      for (int x = 0; x < d.x; ++x, ++i) {
        const glm::dvec3 x0 = glm::dvec3(x, y, z) + 0.5;
        const layout::BricksLayout::Lookup at = bricks->lookup(x0);
        ASSERT_EQ(at.level, 0) << x << "," << y << "," << z;
        const glm::ivec3 brick = glm::ivec3(x, y, z) / 12;
        const glm::dvec3 inSlot = glm::mod(at.texel, 14.0);
        // The slot's first texel is the apron: voxel brick*12 - 1.
        ASSERT_EQ(glm::dvec3(brick * 12) - 1.0 + inSlot, x0) << x << "," << y << "," << z;
      }
  // The GPU's sampleVolume() at every voxel centre is the voxel, exactly.
  layout::LayoutProbe probe(c);
  const std::vector<float> got = probe.sample(*bricks, centres);
  ASSERT_EQ(got.size(), centres.size());
  for (std::size_t k = 0; k < got.size(); ++k) {
    ASSERT_NEAR(got[k] * 255.0, v->valueAtIndex(k), 1e-3) << k;
  }
}

TEST(BricksRender, OnlyCoarseBricksResidentGivesTheCoarseImageWithoutHoles) {
  gpu::GlContext& c = test::gpuContext();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  // 64^3 in 16^3 bricks: levels 64, 32, 16; the pinned coarsest is one brick.
  const auto v = std::make_shared<const Volume>(makeSheppLogan({64, 64, 64}));
  auto pyramid = std::make_shared<lod::InCoreMultiresSource>(v, 16);
  ASSERT_EQ(pyramid->levelCount(), 3);
  auto bricks = layout::BricksLayout::create(pyramid, limits, c.ledger(), smallBricks(16));
  const Volume& coarse = pyramid->level(2);
  Volume coarseShape = coarse;         // spacing 4: the full volume's box
  coarseShape.setWindow(v->window());  // normalised like the full volume, not by its own range
  auto coarse3d = layout::Texture3DLayout::create(coarseShape, limits, c.ledger());
  const Camera cam = viewOf(*v, 30, 20);
  const Image viaBricks = renderWith(c, *v, *bricks, cam);  // no update(): only level 2
  RenderSettings sameStep;  // the same world step as the bricked render's 0.5 level-0 voxel
  sameStep.stepVoxels = RenderSettings().stepVoxels / 4.0;
  const Image viaCoarse = renderWith(c, coarseShape, *coarse3d, cam, sameStep);
  const double db = psnr(viaBricks, viaCoarse);
  EXPECT_GE(db, 40.0);
  // And once refined it is the full-resolution image, not the coarse one.
  refine(*bricks, cam, visibleTf());
  auto full3d = layout::Texture3DLayout::create(*v, limits, c.ledger());
  const Image refined = renderWith(c, *v, *bricks, cam);
  const Image full = renderWith(c, *v, *full3d, cam);
  EXPECT_GE(psnr(refined, full), 45.0);
  EXPECT_LT(psnr(viaBricks, full), psnr(refined, full));
  std::printf("  [measured] coarse bricks vs coarse texture3d %.2f dB; refined vs full %.2f dB\n",
              db, psnr(refined, full));
}

TEST(BricksRender, VolumeFourTimesTheBudgetStaysWithinTheLedger) {
  auto context = gpu::GlContext::createHeadless();  // its own ledger: a clean peak
  gpu::GlContext& c = *context;
  gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  limits.profile = "test-budget";
  // 192^3 u8 = 6.75 MiB of voxels; the profile allows a quarter of that.
  auto source = std::make_shared<lod::ProceduralMultiresSource>("head:192");
  const std::uint64_t volumeBytes = 192ull * 192 * 192;
  limits.textureBudget = volumeBytes / 4;
  const std::uint64_t before = c.ledger().totalBytes();
  c.ledger().setBudget(limits.textureBudget);
  {
    const lod::MultiresVolumeSource streamed(source);
    render::TechniqueOnVolume t = render::createTechnique(
        "raycast", c, limits, streamed, {.imageSize = {kImage, kImage}, .skipBlock = 8});
    ASSERT_EQ(t.upload.plan.layout.layout, "bricks") << t.upload.plan.reason;
    EXPECT_NE(t.upload.plan.reason.find("not texture3d"), std::string::npos);
    auto& bricks = dynamic_cast<layout::BricksLayout&>(*t.upload.layout);
    t.technique->setTransferFunction(visibleTf());
    Camera cam = viewOf(streamed.shape(), 25, 15);
    cam.zoom = 2.0;  // close: the view wants level 0 where the budget cannot hold it all
    layout::BricksFrame f;
    refine(bricks, cam, visibleTf(), &f);
    const Image img = t.technique->renderImage(cam, RenderSettings(), kImage, kImage);
    EXPECT_LE(c.ledger().peakBytes() - before, limits.textureBudget);
    EXPECT_LE(bricks.textureBytes() + t.technique->ownTextureBytes(), limits.textureBudget);
    std::string levels;
    for (std::size_t l = 0; l < f.wantedPerLevel.size(); ++l) {
      levels += " L" + std::to_string(l) + ":" + std::to_string(f.wantedPerLevel[l]);
    }
    std::printf(
        "  [measured] 6.75 MiB volume, 1.69 MiB budget: ledger peak %llu bytes, %d slots, "
        "bricks per level%s%s\n",
        static_cast<unsigned long long>(c.ledger().peakBytes() - before), bricks.slotCount(),
        levels.c_str(), f.limitedByBudget ? " (budget-limited)" : "");
    // The image is the volume's, at the levels the budget allowed.
    const auto inCore =
        std::make_shared<const Volume>(source->readBox(0, {glm::ivec3(0), glm::ivec3(192)}));
    const Image ref = renderReference(*inCore, visibleTf(), cam, RenderSettings(), kImage, kImage);
    EXPECT_GE(psnr(img, ref), 20.0);
    std::printf("  [measured] budget-limited bricks vs full-resolution reference %.2f dB\n",
                psnr(img, ref));
  }
  context.reset();
  test::gpuContext();
}

TEST(BricksRender, FailingReadsLeaveTheCoarserLevelAndComplete) {
  gpu::GlContext& c = test::gpuContext();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  const auto v = std::make_shared<const Volume>(makeSheppLogan({64, 64, 64}));
  auto flaky =
      std::make_shared<FlakySource>(std::make_shared<lod::InCoreMultiresSource>(v, 16), 16);
  layout::BricksOptions o = smallBricks(16);
  o.workers = 2;  // failures arrive from reader threads, as in use
  auto bricks = layout::BricksLayout::create(flaky, limits, c.ledger(), o);
  const Camera cam = viewOf(*v, 30, 20);
  layout::BricksFrame f;
  refine(*bricks, cam, visibleTf(), &f);
  EXPECT_TRUE(f.complete);
  EXPECT_GT(f.failing, 0);
  EXPECT_GT(f.cellsPerLevel[1], 0) << "failed level-0 cells show level 1";
  EXPECT_GT(f.cellsPerLevel[0], 0);
  EXPECT_GT(bricks->streamerStats().readErrors, 0u);
  EXPECT_NE(bricks->streamerStats().lastError.find("HTTP 500"), std::string::npos);
  auto full3d = layout::Texture3DLayout::create(*v, limits, c.ledger());
  const double db = psnr(renderWith(c, *v, *bricks, cam), renderWith(c, *v, *full3d, cam));
  EXPECT_GE(db, 25.0);
  std::printf("  [measured] %d bricks failing, %d cells at level 1: %.2f dB vs full resolution\n",
              f.failing, f.cellsPerLevel[1], db);
}

// A small bright finding in empty space (2x2x2 voxels at odd coordinates):
// the coarse levels average it to a dim value (32 of 255 at level 1) that a
// TF showing only bright values makes transparent. The bricks
// under it must still be read and show it (the mean pyramid's bound), while
// the empty bricks around are left unread.
TEST(BricksRender, ASmallBrightFindingUnderDimCoarseBricksIsReadAndShown) {
  gpu::GlContext& c = test::gpuContext();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  auto v = std::make_shared<Volume>(Volume::allocate({64, 64, 64}, ScalarType::U8));
  for (int z = 33; z < 35; ++z)
    for (int y = 29; y < 31; ++y)
      for (int x = 37; x < 39; ++x) v->setValueAtIndex(v->index(x, y, z), 255.0);
  v->setValueAtIndex(v->index(0, 0, 0), 1.0);  // so the window is not of one value
  v->invalidateRange();
  const TransferFunction bright =
      test::oneColorTf({1.0, 1.0, 1.0}, {{0.0, 0.0}, {0.3, 0.0}, {0.5, 1.0}});
  auto bricks = layout::BricksLayout::create(std::make_shared<lod::InCoreMultiresSource>(v, 8),
                                             limits, c.ledger(), smallBricks(8));
  const Camera cam = viewOf(*v, 20.0, 15.0);
  refine(*bricks, cam, bright);
  const auto inCore = layout::Texture3DLayout::create(*v, limits, c.ledger());
  auto draw = [&](const layout::Layout& layout) {
    render::Raycaster caster(c, *v, layout);
    caster.setTransferFunction(bright);
    return caster.render(cam, RenderSettings(), kImage, kImage);
  };
  const Image viaBricks = draw(*bricks), viaInCore = draw(*inCore);
  auto lit = [](const Image& im) {
    int n = 0;
    for (std::size_t i = 0; i < im.rgba().size(); i += 4) n += im.rgba()[i] > 40 ? 1 : 0;
    return n;
  };
  ASSERT_GT(lit(viaInCore), 0) << "the voxel is visible in-core";
  EXPECT_GE(lit(viaBricks), lit(viaInCore)) << "the bricked render lost the bright finding";
  EXPECT_GE(psnr(viaBricks, viaInCore), 45.0);
  // 585 bricks over 4 levels (512 at level 0): most of the empty ones stay
  // unread, bounded under coarse bricks of range [0, 0] (at most 8 of 255 a
  // level down, 72 two levels down; the TF starts at 76).
  const lod::StreamerStats s = bricks->streamerStats();
  std::printf("  [measured] small bright finding: %llu of 585 bricks read, lit pixels %d vs %d\n",
              static_cast<unsigned long long>(s.bricksRead), lit(viaBricks), lit(viaInCore));
  EXPECT_LT(s.bricksRead, 585u / 2);
}

// A pyramid whose level is no integer reduction of the one before (64 -> 40
// along y) has no place for its voxels over level 0's box: refused, naming
// the level and the axis. (A level that keeps an axis, microscopy's
// (1, 2, 2), is drawn: BricksAnisotropicPyramidTest.cpp.)
TEST(BricksRender, APyramidWhoseLevelIsNoIntegerReductionIsRefusedNamingTheLevelAndAxis) {
  class OddY final : public lod::MultiresSource {
   public:
    OddY() : shape_(Volume::shapeOnly({64, 64, 16}, ScalarType::U8)) {}
    const Volume& shape() const override { return shape_; }
    int levelCount() const override { return 2; }
    lod::LevelInfo levelInfo(int level) const override {
      return {.dims = level == 0 ? glm::ivec3(64, 64, 16) : glm::ivec3(32, 40, 16),
              .spacing = glm::vec3(1.0f),
              .chunk = {}};
    }
    Volume readBox(int, const lod::VoxelBox& box) const override {
      return Volume::allocate(box.size(), ScalarType::U8);
    }
    std::string describe() const override { return "odd-y.ome.zarr"; }

   private:
    Volume shape_;
  };
  gpu::GlContext& c = test::gpuContext();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  try {
    layout::BricksLayout::create(std::make_shared<OddY>(), limits, c.ledger(), smallBricks(16));
    ADD_FAILURE() << "a level of 64 -> 40 voxels was accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("odd-y.ome.zarr: level 1 (32x40x16) does not reduce level 0 (64x64x16) by "
                     "an integer factor along y"),
              std::string::npos)
        << m;
    EXPECT_NE(m.find("--layout texture3d"), std::string::npos) << m;
  }
}
