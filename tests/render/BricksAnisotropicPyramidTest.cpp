// The bricks layout over a pyramid that keeps z (microscopy's (1, 2, 2)
// scales): every level is drawn where its voxels lie, per axis. Each level
// shown alone (the pyramid cut after it, so the pinned coarsest level is
// what every cell shows) is compared, composite and MIP, with the same level
// rendered in core (texture3d on ES 3, mosaic on ES 2, over level 0's box)
// and with the CPU reference (reference::PyramidLevelReconstruction of
// lod::readLevel); drawn with 2^l on every axis, as before, the level would
// be squeezed into the first 2^-l of z (the "bright rectangle" of MIP). The
// whole pyramid refined to level 0 equals the in-core volume.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "support/EachApi.h"
#include "support/GpuTestContext.h"
#include "support/TestCameras.h"
#include "support/TestTransferFunctions.h"
#include "support/WrappedSources.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/BricksLayout.h"
#include "tessera/layout/LayoutProbe.h"
#include "tessera/layout/MosaicLayout.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/lod/LevelScale.h"
#include "tessera/lod/ReadLevel.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/Raycaster.h"

using namespace tessera;

namespace {

constexpr int kImage = 96;
constexpr glm::ivec3 kKeepZ{2, 2, 1};  // (1, 2, 2) in z, y, x order

// 48x40x24 voxels of 0.8 x 0.8 x 2 mm; x and y halve, z is kept:
// 48x40x24, 24x20x24, 12x10x24, 6x5x24. 8 divides 48 and 40, so every
// level's box is level 0's.
std::shared_ptr<Volume> microscopyLike() {
  auto v = std::make_shared<Volume>(makeSheppLogan({48, 40, 24}));
  v->setSpacing({0.8, 0.8, 2.0});
  return v;
}

// Levels 0..last of `inner`: `last` is the coarsest, pinned, and with no
// refinement every cell shows it.
class LevelsUpTo final : public test::WrappedSource {
 public:
  LevelsUpTo(std::shared_ptr<const lod::MultiresSource> inner, int last)
      : WrappedSource(std::move(inner), 8), last_(last) {}
  int levelCount() const override { return last_ + 1; }

 private:
  int last_;
};

layout::BricksOptions options(double pixelsPerVoxel) {
  layout::BricksOptions o;
  o.brickSize = 8;
  o.pixelsPerVoxel = pixelsPerVoxel;
  o.workers = 0;  // inline reads: deterministic residency
  return o;
}

layout::BricksFrame refine(layout::BricksLayout& bricks, const Camera& cam,
                           const TransferFunction& tf) {
  layout::BricksFrame f;
  for (int frame = 1; frame <= 400; ++frame) {
    f = bricks.update(cam, kImage, kImage, tf);
    if (f.complete) return f;
    if (f.uploaded == 0) bricks.waitForBricks(20.0);
  }
  ADD_FAILURE() << "bricks never completed";
  return f;
}

RenderSettings mode(RenderMode m) {
  RenderSettings s;
  s.mode = m;
  return s;
}

// The bricks with their empty-space skipping; the in-core level without
// (its blocks are the level's, not level 0's, which the ray caster's step
// grid is laid over).
Image draw(gpu::GlContext& c, const Volume& box, const layout::Layout& layout, const Camera& cam,
           const RenderSettings& settings, bool skip) {
  render::Raycaster caster(c, box, layout);
  caster.setSkipBlockSize(skip ? 8 : 0);
  caster.setTransferFunction(test::visibleTf());
  return caster.render(cam, settings, kImage, kImage);
}

}  // namespace

using BricksAnisotropicPyramid = test::EachApi;
INSTANTIATE_TEST_SUITE_P(Api, BricksAnisotropicPyramid, test::kEveryApi, test::apiParamName);

TEST_P(BricksAnisotropicPyramid, EachLevelIsDrawnWhereItsVoxelsLieOnEveryAxis) {
  gpu::GlContext& c = context();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  const bool es3 = GetParam() == gpu::ApiLevel::Gles3;
  const auto v = microscopyLike();
  const auto pyramid = std::make_shared<lod::InCoreMultiresSource>(v, 8, kKeepZ);
  ASSERT_EQ(pyramid->levelCount(), 4);
  const TransferFunction tf = test::visibleTf();
  for (int level = 1; level < pyramid->levelCount(); ++level) {
    SCOPED_TRACE(level);
    auto bricks = layout::BricksLayout::create(std::make_shared<LevelsUpTo>(pyramid, level), limits,
                                               c.ledger(), options(1e9));
    const Volume levelVolume = lod::readLevel(*pyramid, level);
    const glm::ivec3 scale = lod::levelScale(*pyramid, level);
    ASSERT_EQ(scale, glm::ivec3(1 << level, 1 << level, 1));
    const PyramidLevelReconstruction field(levelVolume, scale, v->dims());
    // Drawn as before, with 2^l on every axis: the test must tell it apart.
    const PyramidLevelReconstruction halvingEveryAxis(levelVolume, glm::ivec3(1 << level),
                                                      v->dims());
    std::unique_ptr<layout::Layout> inCore =
        es3 ? std::unique_ptr<layout::Layout>(
                  layout::Texture3DLayout::create(levelVolume, limits, c.ledger()))
            : std::unique_ptr<layout::Layout>(
                  layout::MosaicLayout::create(levelVolume, limits, c.ledger()));
    for (const auto& [az, el] : {std::pair{35.0, 25.0}, std::pair{100.0, -30.0}}) {
      const Camera cam = test::orbitCamera(v->extent(), az, el);
      const layout::BricksFrame f = refine(*bricks, cam, tf);
      // 6x5x3 level-0 cells, each shown at `level` or known to be empty.
      ASSERT_GT(f.cellsPerLevel[static_cast<std::size_t>(level)], 0);
      EXPECT_EQ(f.cellsPerLevel[static_cast<std::size_t>(level)] + f.cellsPerLevel.back(), 90);
      for (const RenderMode m : {RenderMode::Composite, RenderMode::Mip}) {
        const RenderSettings s = mode(m);
        const Image viaBricks = draw(c, *v, *bricks, cam, s, true);
        const Image viaInCore = draw(c, *v, *inCore, cam, s, false);
        const Image ref = renderReference(*v, field, tf, cam, s, kImage, kImage);
        const Image wrong = renderReference(*v, halvingEveryAxis, tf, cam, s, kImage, kImage);
        const double vsInCore = psnr(viaBricks, viaInCore);
        const double vsRef = psnr(viaBricks, ref);
        const double vsWrong = psnr(viaBricks, wrong);
        EXPECT_GE(vsInCore, 45.0) << renderModeToName(m);
        EXPECT_GE(vsRef, 45.0) << renderModeToName(m);
        EXPECT_LT(vsWrong, 30.0) << renderModeToName(m);
        std::printf(
            "  [measured] %s level %d (%dx%dx%d) %s az %g: bricks vs %s of the level %.2f dB, "
            "vs reference %.2f dB (vs the level drawn 2^l on every axis %.2f dB)\n",
            es3 ? "ES3" : "ES2", level, levelVolume.dims().x, levelVolume.dims().y,
            levelVolume.dims().z, std::string(renderModeToName(m)).c_str(), az,
            inCore->name().c_str(), vsInCore, vsRef, vsWrong);
      }
    }
  }
}

// sampleVolume() at every level-0 voxel centre, each level shown alone, is
// the reference's field there (PyramidLevelReconstruction of readLevel):
// the shader and its CPU twin put every level's voxels at the same place,
// and not where 2^l on every axis would.
TEST_P(BricksAnisotropicPyramid, EveryLevelZeroVoxelCentreReadsTheReferenceField) {
  gpu::GlContext& c = context();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  const auto v = microscopyLike();
  const auto pyramid = std::make_shared<lod::InCoreMultiresSource>(v, 8, kKeepZ);
  const std::vector<glm::vec3> centres = layout::LayoutProbe::voxelCentres(v->dims());
  layout::LayoutProbe probe(c);
  for (int level = 1; level < pyramid->levelCount(); ++level) {
    SCOPED_TRACE(level);
    // No update(): no TF has classified a cell, every one shows `level`.
    auto bricks = layout::BricksLayout::create(std::make_shared<LevelsUpTo>(pyramid, level), limits,
                                               c.ledger(), options(1e9));
    const Volume levelVolume = lod::readLevel(*pyramid, level);
    const PyramidLevelReconstruction field(levelVolume, lod::levelScale(*pyramid, level),
                                           v->dims());
    const PyramidLevelReconstruction halvingEveryAxis(levelVolume, glm::ivec3(1 << level),
                                                      v->dims());
    const std::vector<float> got = probe.sample(*bricks, centres);
    ASSERT_EQ(got.size(), centres.size());
    const layout::ValueMapping m = bricks->rawFromStored();
    double worst = 0.0, worstIfHalved = 0.0;
    for (std::size_t k = 0; k < got.size(); ++k) {
      const double raw = m.scale * got[k] + m.offset;
      const glm::dvec3 p(centres[k]);
      worst = std::max(worst, std::abs(raw - field.value(p)));
      worstIfHalved = std::max(worstIfHalved, std::abs(raw - halvingEveryAxis.value(p)));
    }
    // u8 values 0..255. Level-0 centres fall a quarter or three quarters
    // between level voxels along x and y, where the sampler's fixed-point
    // coordinates (8 fractional bits on llvmpipe) weigh a neighbour up to
    // 1/256 off: at most one grey level across the phantom's 255-step edges
    // (0.0006 at level 0, where centres meet centres).
    EXPECT_LE(worst, 1.5);
    EXPECT_GE(worstIfHalved, 50.0);
    std::printf(
        "  [measured] %s level %d: worst |sampleVolume - reference field| %.4f of 255 (the "
        "level placed 2^l on every axis: %.1f)\n",
        test::apiName(GetParam()), level, worst, worstIfHalved);
  }
}

TEST_P(BricksAnisotropicPyramid, RefinedToLevelZeroItIsTheInCoreVolume) {
  gpu::GlContext& c = context();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  const bool es3 = GetParam() == gpu::ApiLevel::Gles3;
  const auto v = microscopyLike();
  auto bricks = layout::BricksLayout::create(
      std::make_shared<lod::InCoreMultiresSource>(v, 8, kKeepZ), limits, c.ledger(), options(0.05));
  std::unique_ptr<layout::Layout> inCore =
      es3 ? std::unique_ptr<layout::Layout>(layout::Texture3DLayout::create(*v, limits, c.ledger()))
          : std::unique_ptr<layout::Layout>(layout::MosaicLayout::create(*v, limits, c.ledger()));
  const Camera cam = test::orbitCamera(v->extent(), -60.0, 20.0);
  const layout::BricksFrame f = refine(*bricks, cam, test::visibleTf());
  EXPECT_EQ(f.cellsPerLevel[0] + f.cellsPerLevel.back(), 90) << "all at level 0 or empty";
  for (const RenderMode m : {RenderMode::Composite, RenderMode::Mip}) {
    const RenderSettings s = mode(m);
    const Image viaBricks = draw(c, *v, *bricks, cam, s, true);
    const double vsInCore = psnr(viaBricks, draw(c, *v, *inCore, cam, s, true));
    const double vsRef =
        psnr(viaBricks, renderReference(*v, test::visibleTf(), cam, s, kImage, kImage));
    EXPECT_GE(vsInCore, 45.0) << renderModeToName(m);
    EXPECT_GE(vsRef, 45.0) << renderModeToName(m);
    std::printf("  [measured] %s level 0 %s: bricks vs %s %.2f dB, vs reference %.2f dB\n",
                es3 ? "ES3" : "ES2", std::string(renderModeToName(m)).c_str(),
                inCore->name().c_str(), vsInCore, vsRef);
  }
}
