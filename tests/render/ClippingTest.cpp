// Clip planes and the crop box: every technique on every
// layout, ES 3.0 and ES 2.0, against the clipped reference; moving a plane
// by less than a sample step changes no sample on the kept side.
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <memory>
#include <vector>

#include "support/GpuTestContext.h"
#include "support/TestLayouts.h"
#include "support/TestTransferFunctions.h"
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

const char* apiName(gpu::ApiLevel api) {
  return api == gpu::ApiLevel::Gles2 ? "gles2" : "gles3";
}

template <class Body>
void withContext(gpu::ApiLevel api, Body body) {
  gpu::GlContext::Options o;
  o.api = api;
  auto owned = api == gpu::ApiLevel::Gles2 ? gpu::GlContext::createHeadless(o) : nullptr;
  body(owned ? *owned : test::gpuContext());
  owned.reset();
  test::gpuContext();
}

void expectClippedMatchesReference(gpu::ApiLevel api) {
  withContext(api, [&](gpu::GlContext& c) {
    const Volume v = makeSphere({37, 53, 29});
    Camera cam;
    cam.azimuthDeg = 35;
    cam.elevationDeg = 25;
    cam.frame(v.extent());
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
                  apiName(api), l->name().c_str(), cast, slice);
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
      Camera aligned;
      aligned.projection = Projection::Orthographic;
      if (axis == 0) aligned.azimuthDeg = 90;
      if (axis == 2) aligned.elevationDeg = 90;
      aligned.frame(v.extent());
      const double db = psnr(slicer2d.render(aligned, s1, 96, 96),
                             renderReference(v, visibleTf(), aligned, s1, 96, 96));
      std::printf("  [measured] clipped %s slice2d stack %c %.2f dB vs reference\n", apiName(api),
                  "xyz"[axis], db);
      EXPECT_GE(db, 40.0) << "axis " << axis;
    }
  });
}

}  // namespace

TEST(Clipping, EveryTechniqueAndLayoutMatchesClippedReferenceOnEs3) {
  expectClippedMatchesReference(gpu::ApiLevel::Gles3);
}

TEST(Clipping, EveryTechniqueAndLayoutMatchesClippedReferenceOnEs2) {
  expectClippedMatchesReference(gpu::ApiLevel::Gles2);
}

// Looking down -z orthographically, samples sit at z = top - (k + 0.5) ds.
// A plane cutting away z > d between samples 10 and 11, moved by 0.3 ds,
// leaves every kept sample where it was: the image does not change at all.
// A whole step does change it (the test has teeth).
TEST(Clipping, MovingAPlaneBySubStepKeepsTheSamplesOnTheKeptSide) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSheppLogan({40, 40, 40});
  auto t3d = layout::Texture3DLayout::create(v, gpu::DeviceLimits::of(c.caps()), c.ledger());
  render::Raycaster caster(c, v, *t3d);
  caster.setTransferFunction(visibleTf());
  Camera cam;
  cam.projection = Projection::Orthographic;
  cam.elevationDeg = 90;
  cam.frame(v.extent());
  RenderSettings s;
  const double ds = s.stepVoxels * v.spacing().z;
  const double top = v.extent().z / 2.0;
  auto renderAt = [&](double d) {
    RenderSettings clipped = s;
    clipped.clipping.planes.push_back({{0.0, 0.0, 1.0}, d});
    return caster.render(cam, clipped, 80, 80);
  };
  const double d = top - 10.6 * ds;
  const Image a = renderAt(d);
  const Image b = renderAt(d - 0.3 * ds);
  const Image stepped = renderAt(d - ds);
  EXPECT_EQ(psnr(a, b), std::numeric_limits<double>::infinity());
  EXPECT_LT(psnr(a, stepped), 50.0) << "a whole step moves the cut";
  EXPECT_LT(psnr(a, caster.render(cam, s, 80, 80)), 40.0) << "the plane must cut";
  RenderSettings clipped = s;
  clipped.clipping.planes.push_back({{0.0, 0.0, 1.0}, d});
  const double db = psnr(a, renderReference(v, visibleTf(), cam, clipped, 80, 80));
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
