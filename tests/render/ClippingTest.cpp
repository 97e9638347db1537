// Clip planes and the crop box: every technique on every
// layout, ES 3.0 and ES 2.0, against the clipped reference; moving a plane
// by less than a sample step changes no sample on the kept side.
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <memory>
#include <vector>

#include "render/SubStepClip.h"
#include "support/EachApi.h"
#include "support/GpuTestContext.h"
#include "support/TestCameras.h"
#include "support/TestLayouts.h"
#include "support/TestTransferFunctions.h"
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

using test::layoutsFor;
using test::visibleTf;

// Two planes and a crop box that cut into the sphere's inside.
RenderSettings clippedSettings() {
  RenderSettings s;
  s.stepVoxels = 0.5;
  s.ertThreshold = 1.0;  // slicing cannot stop early
  s.clipping.planes.push_back({{0.0, 1.0, 0.0}, 2.0});
  s.clipping.planes.push_back({{-1.0, 0.0, -1.0}, 6.0});
  s.clipping.cropMin = {0.1, 0.0, 0.15};
  s.clipping.cropMax = {0.85, 1.0, 1.0};
  return s;
}

}  // namespace

using ClippingOnEachApi = test::EachApi;
INSTANTIATE_TEST_SUITE_P(Api, ClippingOnEachApi, test::kEveryApi, test::apiParamName);

TEST_P(ClippingOnEachApi, EveryTechniqueAndLayoutMatchesClippedReference) {
  const gpu::ApiLevel api = GetParam();
  test::withApi(api, [&](gpu::GlContext& c) {
    const Volume v = makeSphere({37, 53, 29});
    Camera cam = test::orbitCamera(v.extent(), 35, 25);
    const RenderSettings s = clippedSettings();
    RenderSettings plain = s;
    plain.clipping = {};
    const Image ref = renderReference(v, visibleTf(), cam, s, 96, 96);
    ASSERT_LT(psnr(ref, renderReference(v, visibleTf(), cam, plain, 96, 96)), 25.0)
        << "the clipping must show";
    for (const auto& l : layoutsFor(c, v)) {
      render::Raycaster caster(c, v, *l);
      caster.setTransferFunction(visibleTf());
      render::Slice3DRenderer slicer(c, v, *l);
      slicer.setTransferFunction(visibleTf());
      const double cast = psnr(caster.render(cam, s, 96, 96), ref);
      const double slice = psnr(slicer.render(cam, s, 96, 96), ref);
      std::printf("  [measured] clipped %s %-13s raycast %.2f dB, slice3d %.2f dB vs reference\n",
                  test::apiName(api), l->name().c_str(), cast, slice);
      EXPECT_GE(cast, 40.0) << l->name();
      EXPECT_GE(slice, 40.0) << l->name();
    }
    // slice2d: orthographic along each stack at a 1-voxel step (its planes
    // are then the reference's samples).
    RenderSettings s1 = s;
    s1.stepVoxels = 1.0;
    render::Slice2DRenderer slicer2d(c, v, {});
    slicer2d.setTransferFunction(visibleTf());
    for (int axis = 0; axis < 3; ++axis) {
      const Camera aligned = test::axisCamera(v.extent(), axis, Projection::Orthographic);
      const double db = psnr(slicer2d.render(aligned, s1, 96, 96),
                             renderReference(v, visibleTf(), aligned, s1, 96, 96));
      std::printf("  [measured] clipped %s slice2d stack %c %.2f dB vs reference\n",
                  test::apiName(api), "xyz"[axis], db);
      EXPECT_GE(db, 40.0) << "axis " << axis;
    }
  });
}

// A plane moved by 0.3 of a step (render/SubStepClip.h) leaves the image
// as it was; a whole step does change it (the test has teeth).
TEST(Clipping, MovingAPlaneBySubStepKeepsTheSamplesOnTheKeptSide) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSheppLogan({40, 40, 40});
  test::Texture3DCaster t3d(c, v, visibleTf());
  render::Raycaster& caster = t3d.caster;
  const Camera cam = test::topDownOrthographic(v.extent());
  const test::SubStepClip r = test::renderSubStepClip(caster, v, cam, RenderSettings(), 80);
  EXPECT_EQ(psnr(r.cut, r.nudged), std::numeric_limits<double>::infinity());
  EXPECT_LT(psnr(r.cut, r.stepped), 50.0) << "a whole step moves the cut";
  EXPECT_LT(psnr(r.cut, r.uncut), 40.0) << "the plane must cut";
  const double db = psnr(r.cut, renderReference(v, visibleTf(), cam, r.clipped, 80, 80));
  std::printf("  [measured] clipped ortho raycast vs reference %.2f dB\n", db);
  EXPECT_GE(db, 40.0);
}

TEST(Clipping, BadPlanesAndCropBoxesAreRejected) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSphere({16, 16, 16});
  auto t3d = layout::Texture3DLayout::create(v, gpu::DeviceLimits::of(c.caps()), c.ledger());
  render::Raycaster caster(c, v, *t3d);
  Camera cam;
  cam.frame(v.extent());
  RenderSettings s;
  s.clipping.planes.assign(7, ClipPlane{});
  EXPECT_THROW(caster.render(cam, s, 16, 16), InputError);
  s.clipping.planes.assign(1, ClipPlane{{0.0, 0.0, 0.0}, 1.0});
  EXPECT_THROW(caster.render(cam, s, 16, 16), InputError);
  s.clipping.planes.clear();
  s.clipping.cropMin = {0.5, 0.0, 0.0};
  s.clipping.cropMax = {0.4, 1.0, 1.0};
  EXPECT_THROW(caster.render(cam, s, 16, 16), InputError);
}
