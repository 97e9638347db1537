// MinIP and average-intensity projection: the ray caster
// on every layout, ES 3.0 and ES 2.0, against the reference; the slicers say
// they cannot.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <vector>

#include "support/EachApi.h"
#include "support/GpuTestContext.h"
#include "support/TestCameras.h"
#include "support/TestLayouts.h"
#include "support/Texture3DCaster.h"
#include "tessera/core/Error.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/Raycaster.h"
#include "tessera/render/Slice2DRenderer.h"
#include "tessera/render/Slice3DRenderer.h"

using namespace tessera;

namespace {

const char* modeName(RenderMode m) {
  return m == RenderMode::MinIp ? "minip" : m == RenderMode::Average ? "average" : "mip";
}

}  // namespace

using ProjectionModesOnEachApi = test::EachApi;
INSTANTIATE_TEST_SUITE_P(Api, ProjectionModesOnEachApi, test::kEveryApi, test::apiParamName);

TEST_P(ProjectionModesOnEachApi, MinIpAndAverageMatchReferenceOnEveryLayout) {
  const gpu::ApiLevel api = GetParam();
  gpu::GlContext& c = context();
  const Volume v = makeSheppLogan({37, 53, 29});
  const auto layouts = test::gridLayouts(c, api, v, 128);
  Camera cam = test::orbitCamera(v.extent(), 35, 25);
  const TransferFunction grey = TransferFunction::preset("grey");
  RenderSettings mip;
  mip.mode = RenderMode::Mip;
  const Image mipRef = renderReference(v, grey, cam, mip, 80, 80);
  for (RenderMode mode : {RenderMode::MinIp, RenderMode::Average}) {
    RenderSettings s;
    s.mode = mode;
    // A crop box, so that MinIP is not just the phantom's dark rim.
    s.clipping.cropMin = {0.2, 0.2, 0.2};
    s.clipping.cropMax = {0.8, 0.8, 0.8};
    const Image ref = renderReference(v, grey, cam, s, 80, 80);
    EXPECT_LT(psnr(ref, mipRef), 30.0) << modeName(mode) << " must differ from MIP";
    for (const auto& l : layouts) {
      render::Raycaster caster(c, v, *l);
      caster.setTransferFunction(grey);
      const double db = psnr(caster.render(cam, s, 80, 80), ref);
      std::printf("  [measured] %s %-7s %-13s raycast %.2f dB vs reference\n",
                  api == gpu::ApiLevel::Gles2 ? "gles2" : "gles3", modeName(mode),
                  l->name().c_str(), db);
      EXPECT_GE(db, 40.0) << modeName(mode) << " " << l->name();
    }
  }
}

// The average of a volume whose every voxel is 100 (window 0..200) is 0.5.
TEST(ProjectionModes, AverageOfAConstantVolumeIsItsValue) {
  Volume v = Volume::allocate({12, 10, 8}, ScalarType::U8, "constant");
  for (std::size_t i = 0; i < static_cast<std::size_t>(v.voxelCount()); ++i) {
    v.setValueAtIndex(i, 100.0);
  }
  v.invalidateRange();
  v.setWindow({0.0, 200.0});
  gpu::GlContext& c = test::gpuContext();
  test::Texture3DCaster t3d(c, v, TransferFunction::preset("grey"));
  render::Raycaster& caster = t3d.caster;
  Camera cam = test::orbitCamera(v.extent(), 20, 0);
  RenderSettings s;
  s.mode = RenderMode::Average;
  const Image img = caster.render(cam, s, 32, 32);
  const std::uint8_t* centre = img.pixel(16, 16);
  const int expected =
      static_cast<int>(std::lround(TransferFunction::preset("grey").color(0.5).x * 255.0));
  EXPECT_NEAR(centre[0], expected, 1);
  EXPECT_EQ(centre[3], 255);
}

TEST(ProjectionModes, SlicersSayMinIpAndAverageNeedTheRayCaster) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSphere({16, 16, 16});
  auto t3d = layout::Texture3DLayout::create(v, gpu::DeviceLimits::of(c.caps()), c.ledger());
  render::Slice3DRenderer slice3d(c, v, *t3d);
  render::Slice2DRenderer slice2d(c, v, {});
  Camera cam;
  cam.frame(v.extent());
  RenderSettings s;
  s.mode = RenderMode::MinIp;
  EXPECT_THROW(slice3d.render(cam, s, 16, 16), InputError);
  s.mode = RenderMode::Average;
  EXPECT_THROW(slice2d.render(cam, s, 16, 16), InputError);
}
