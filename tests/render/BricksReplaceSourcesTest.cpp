// BricksLayout::replaceSources (layout/StreamingLayout.h): another pyramid
// of the same grid (a store's next time point) streamed into the atlas,
// page table and walk pages made for the first, on ES 3 (3D atlas) and
// ES 2 (mosaic atlas). The frame then equals a layout made for the new
// pyramid alone, and the ledger holds the same textures before and after;
// a pyramid of another grid is refused with the layout as it was.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "support/EachApi.h"
#include "support/GpuTestContext.h"
#include "support/TestCameras.h"
#include "support/TestTransferFunctions.h"
#include "tessera/gpu/DeviceSession.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/BricksLayout.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/render/Raycaster.h"

using namespace tessera;
using test::visibleTf;

namespace {

constexpr int kImage = 96;
constexpr glm::ivec3 kDims{37, 53, 29};  // 4x5x3 bricks of 12, the last ones partial

std::shared_ptr<const lod::MultiresSource> pyramidOf(Volume v) {
  return std::make_shared<lod::InCoreMultiresSource>(std::make_shared<const Volume>(std::move(v)),
                                                     8);
}

layout::BricksOptions smallBricks() {
  layout::BricksOptions o;
  o.brickSize = 12;
  o.pixelsPerVoxel = 0.05;  // every brick at level 0 for these small volumes
  o.workers = 0;            // inline reads: deterministic residency
  return o;
}

void refine(layout::BricksLayout& bricks, const Camera& cam) {
  for (int frame = 1; frame <= 400; ++frame) {
    const layout::BricksFrame f = bricks.update(cam, kImage, kImage, visibleTf());
    if (f.complete) return;
    if (f.uploaded == 0) bricks.waitForBricks(20.0);
  }
  ADD_FAILURE() << "bricks never completed";
}

Image draw(gpu::GlContext& c, const Volume& shape, layout::BricksLayout& bricks,
           const Camera& cam) {
  refine(bricks, cam);
  render::Raycaster caster(c, shape, bricks);
  caster.setSkipBlockSize(8);
  caster.setTransferFunction(visibleTf());
  return caster.render(cam, RenderSettings(), kImage, kImage);
}

gpu::DeviceLimits limitsFor(gpu::GlContext& c, gpu::ApiLevel api) {
  gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  // ES 2: 256^2 mosaics of 23 slots each, the atlas over several textures.
  if (api == gpu::ApiLevel::Gles2) limits.max2DTextureSize = 256;
  return limits;
}

}  // namespace

using BricksReplaceSourcesOnEachApi = test::EachApi;
INSTANTIATE_TEST_SUITE_P(Api, BricksReplaceSourcesOnEachApi, test::kEveryApi, test::apiParamName);

TEST_P(BricksReplaceSourcesOnEachApi, AnotherPyramidDrawsAsItsOwnLayoutInTheSameTextures) {
  gpu::GlContext& c = context();
  const gpu::DeviceLimits limits = limitsFor(c, GetParam());
  const Volume first = makeSheppLogan(kDims);
  const Volume second = makeSphere(kDims);
  const Camera cam = test::orbitCamera(first.extent(), 35.0, 25.0);
  auto bricks = layout::BricksLayout::create(pyramidOf(first), limits, c.ledger(), smallBricks());
  const Image before = draw(c, first, *bricks, cam);
  const std::size_t textures = c.ledger().count();
  const std::uint64_t bytes = c.ledger().totalBytes();
  const std::uint64_t version = bricks->contentVersion();

  ASSERT_TRUE(bricks->replaceSources({pyramidOf(second)}));
  EXPECT_EQ(bricks->sourcesReplaced(), 1);
  EXPECT_GT(bricks->contentVersion(), version);  // the block grid is made again
  const Image replaced = draw(c, second, *bricks, cam);
  EXPECT_EQ(c.ledger().count(), textures);
  EXPECT_EQ(c.ledger().totalBytes(), bytes);

  auto own = layout::BricksLayout::create(pyramidOf(second), limits, c.ledger(), smallBricks());
  const Image alone = draw(c, second, *own, cam);
  const double db = psnr(replaced, alone);
  const double vsFirst = psnr(replaced, before);
  std::printf(
      "  [measured] %s: replaced vs its own layout %.1f dB, vs the first pyramid's "
      "frame %.1f dB; %zu textures, %llu bytes before and after\n",
      test::apiName(GetParam()), db, vsFirst, textures, static_cast<unsigned long long>(bytes));
  EXPECT_GE(db, 60.0);
  EXPECT_LT(vsFirst, 30.0);
}

TEST_P(BricksReplaceSourcesOnEachApi, APyramidOfAnotherGridIsRefusedAndTheLayoutStays) {
  gpu::GlContext& c = context();
  const gpu::DeviceLimits limits = limitsFor(c, GetParam());
  const Volume first = makeSheppLogan(kDims);
  const Camera cam = test::orbitCamera(first.extent(), 35.0, 25.0);
  auto bricks = layout::BricksLayout::create(pyramidOf(first), limits, c.ledger(), smallBricks());
  const Image before = draw(c, first, *bricks, cam);
  EXPECT_FALSE(bricks->replaceSources({pyramidOf(makeSphere({37, 53, 30}))}));
  EXPECT_FALSE(bricks->replaceSources({pyramidOf(first), pyramidOf(first)}));  // two channels
  EXPECT_EQ(bricks->sourcesReplaced(), 0);
  const Image after = draw(c, first, *bricks, cam);
  EXPECT_TRUE(std::isinf(psnr(after, before))) << psnr(after, before) << " dB";
}
