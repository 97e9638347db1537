// View-aligned slicing: against the CPU reference, across layouts
// and API levels, and the static proxy geometry.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <glm/geometric.hpp>

#include "support/ChannelStore.h"
#include "support/GpuTestContext.h"
#include "support/TestCameras.h"
#include "support/TestTransferFunctions.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/TexelFormat.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/MosaicLayout.h"
#include "tessera/layout/PackedMosaicLayout.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/Slice3DRenderer.h"

using namespace tessera;

namespace {

using test::visibleTf;

// Slicing has no early termination; the reference is told the same.
RenderSettings halfVoxel() {
  RenderSettings s;
  s.stepVoxels = 0.5;
  s.ertThreshold = 1.0;
  return s;
}

Camera obliqueCamera(const Volume& v) {
  return test::orbitCamera(v.extent(), 35, 25);
}

Image sliceWith(gpu::GlContext& c, const Volume& v, const layout::Layout& layout, const Camera& cam,
                const RenderSettings& s, int size) {
  render::Slice3DRenderer r(c, v, layout);
  r.setTransferFunction(visibleTf());
  return r.render(cam, s, size, size);
}

}  // namespace

TEST(Slice3D, HalfVoxelSpacingMatchesReferenceOnTexture3d) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSheppLogan({48, 56, 40});
  auto t3d = layout::Texture3DLayout::create(v, gpu::DeviceLimits::of(c.caps()), c.ledger());
  const RenderSettings s = halfVoxel();
  for (Projection projection : {Projection::Perspective, Projection::Orthographic}) {
    Camera cam = obliqueCamera(v);
    cam.projection = projection;
    const Image img = sliceWith(c, v, *t3d, cam, s, 96);
    const Image ref = renderReference(v, visibleTf(), cam, s, 96, 96);
    const double db = psnr(img, ref);
    const double sim = ssim(img, ref);
    std::printf("  [measured] slice3d texture3d %s vs reference: %.2f dB, SSIM %.4f\n",
                projection == Projection::Perspective ? "perspective" : "orthographic", db, sim);
    EXPECT_GE(db, 35.0);
    EXPECT_GE(sim, 0.95);
  }
}

TEST(Slice3D, MosaicLayoutsMatchTexture3d) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSheppLogan({37, 53, 29});
  gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  auto t3d = layout::Texture3DLayout::create(v, limits, c.ledger());
  auto mosaic = layout::MosaicLayout::create(v, limits, c.ledger());
  limits.max2DTextureSize = 128;  // packed across channels and textures
  auto packed = layout::PackedMosaicLayout::create(v, limits, c.ledger(), 6);
  RenderSettings s = halfVoxel();
  const Camera cam = obliqueCamera(v);
  const Image via3d = sliceWith(c, v, *t3d, cam, s, 96);
  const double dbMosaic = psnr(sliceWith(c, v, *mosaic, cam, s, 96), via3d);
  const double dbPacked = psnr(sliceWith(c, v, *packed, cam, s, 96), via3d);
  std::printf("  [measured] slice3d mosaic vs texture3d %.2f dB, packed vs texture3d %.2f dB\n",
              dbMosaic, dbPacked);
  EXPECT_GE(dbMosaic, 45.0);
  EXPECT_GE(dbPacked, 45.0);
}

TEST(Slice3D, Es2ContextRendersMosaicAndPackedLayouts) {
  gpu::GlContext::Options o;
  o.api = gpu::ApiLevel::Gles2;
  auto c = gpu::GlContext::createHeadless(o);
  {
    const Volume v = makeSheppLogan({48, 56, 40});
    gpu::DeviceLimits limits = gpu::DeviceLimits::of(c->caps());
    auto mosaic = layout::MosaicLayout::create(v, limits, c->ledger());
    limits.max2DTextureSize = 128;
    auto packed = layout::PackedMosaicLayout::create(v, limits, c->ledger(), 6);
    // ES 2 accumulates in half floats where the context renders to them
    // (EXT_color_buffer_half_float), RGBA8 otherwise; a 1-voxel step keeps
    // the RGBA8 case's rounding small too.
    RenderSettings s = halfVoxel();
    s.stepVoxels = 1.0;
    const Camera cam = obliqueCamera(v);
    const Image ref = renderReference(v, visibleTf(), cam, s, 96, 96);
    for (const layout::Layout* l : {static_cast<const layout::Layout*>(mosaic.get()),
                                    static_cast<const layout::Layout*>(packed.get())}) {
      render::Slice3DRenderer r(*c, v, *l);
      EXPECT_EQ(r.accumulationFormat(),
                limits.halfFloatRenderTargets
                    ? gpu::texelFormatName(gpu::TexelFormat::RgbaHalfUnsized)
                    : std::string("RGBA8"));
      r.setTransferFunction(visibleTf());
      const Image img = r.render(cam, s, 96, 96);
      const double db = psnr(img, ref);
      std::printf("  [measured] slice3d ES2 %s vs reference: %.2f dB, SSIM %.4f\n",
                  l->name().c_str(), db, ssim(img, ref));
      EXPECT_GE(db, 30.0);
    }
  }
  c.reset();
  test::gpuContext();
}

TEST(Slice3D, ProxyGeometryIsBuiltOnceAndNotRebuiltForCameraChanges) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSheppLogan({32, 32, 32});
  auto t3d = layout::Texture3DLayout::create(v, gpu::DeviceLimits::of(c.caps()), c.ledger());
  render::Slice3DRenderer r(c, v, *t3d);
  r.setTransferFunction(visibleTf());
  r.setSliceCount(40);
  RenderSettings s = halfVoxel();
  Camera cam = obliqueCamera(v);
  const Image first = r.render(cam, s, 48, 48);
  const unsigned buffer = r.vertexBufferId();
  EXPECT_EQ(r.geometryBuilds(), 1u);
  EXPECT_EQ(r.vertexBufferBytes(), 40u * 6 * 3 * sizeof(float));
  for (int i = 1; i <= 5; ++i) {
    cam.azimuthDeg += 37;
    cam.elevationDeg = -60 + 25 * i;
    cam.zoom = 1.0 + 0.1 * i;
    cam.projection = i % 2 ? Projection::Orthographic : Projection::Perspective;
    const Image img = r.render(cam, s, 48, 48);
    EXPECT_LT(psnr(img, first), 40.0) << "the view must change";
  }
  EXPECT_EQ(r.geometryBuilds(), 1u);
  EXPECT_EQ(r.vertexBufferId(), buffer);
  r.setSliceCount(80);  // only a new count rebuilds
  r.render(cam, s, 48, 48);
  EXPECT_EQ(r.geometryBuilds(), 2u);
}

TEST(Slice3D, SliceCountSetsTheSpacingOverTheDiagonal) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSheppLogan({30, 40, 20});
  auto t3d = layout::Texture3DLayout::create(v, gpu::DeviceLimits::of(c.caps()), c.ledger());
  render::Slice3DRenderer r(c, v, *t3d);
  RenderSettings s;
  s.stepVoxels = 0.5;
  const double d = glm::length(v.extent());
  const glm::dvec3 sp = v.spacing();
  EXPECT_EQ(r.sliceCountFor(s),
            static_cast<int>(std::ceil(d / (0.5 * std::min({sp.x, sp.y, sp.z})))));
  r.setSliceCount(10);
  EXPECT_DOUBLE_EQ(r.sliceSpacingFor(s), d / 10);
  EXPECT_THROW(r.setSliceCount(-1), InputError);
}

TEST(Slice3D, MipMatchesReference) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSheppLogan({48, 56, 40});
  auto t3d = layout::Texture3DLayout::create(v, gpu::DeviceLimits::of(c.caps()), c.ledger());
  RenderSettings s = halfVoxel();
  s.mode = RenderMode::Mip;
  const Camera cam = obliqueCamera(v);
  render::Slice3DRenderer r(c, v, *t3d);
  r.setTransferFunction(TransferFunction::preset("grey"));
  const Image img = r.render(cam, s, 80, 80);
  const Image ref = renderReference(v, TransferFunction::preset("grey"), cam, s, 80, 80);
  std::printf("  [measured] slice3d MIP vs reference: %.2f dB\n", psnr(img, ref));
  EXPECT_GE(psnr(img, ref), 30.0);
}

// A u16 volume whose voxels are channel 1 of the test channel store (a
// slab across x and z on a background of 100): seen obliquely through a
// grey ramp at a high opacity scale, each plane adds a fraction of an 8-bit
// level to a dim pixel.
Volume slabVolume() {
  const glm::ivec3 d{96, 96, 48};
  Volume v = Volume::allocate(d, ScalarType::U16, "slab");
  std::size_t i = 0;
  for (int z = 0; z < d.z; ++z) {
    for (int y = 0; y < d.y; ++y) {
      for (int x = 0; x < d.x; ++x, ++i)
        v.setValueAtIndex(i, test::channelStoreValue(1, d, x, y, z));
    }
  }
  v.invalidateRange();
  return v;
}

// On an ES 2 profile without float render targets (webgl1-desktop-2012)
// the slices accumulate in RGBA8, where each blend rounds to 8 bits: each
// proxy slice composites a slab of kRgba8SlabSamples planes in the shader,
// dithers and blends once. The translucent slab through 1440 planes (a
// tenth of a voxel apart, as many as the 512x512x200 store takes at half a
// voxel), orthographic and perspective, against the reference; one plane a
// slice (no slabs, dithered) is printed beside it.
TEST(Slice3D, Rgba8AccumulationHolds40DbWithSlabs) {
  gpu::GlContext::Options o;
  o.api = gpu::ApiLevel::Gles2;
  auto c = gpu::GlContext::createHeadless(o);
  {
    const gpu::DeviceLimits limits =
        gpu::effectiveLimits(gpu::DeviceProfile::find("webgl1-desktop-2012"), c->caps());
    ASSERT_FALSE(limits.halfFloatRenderTargets);
    RenderSettings s = halfVoxel();
    s.stepVoxels = 0.1;
    s.opacityScale = 5.0;
    const TransferFunction tf = TransferFunction::preset("grey");
    const Volume v = slabVolume();
    auto mosaic = layout::MosaicLayout::create(v, limits, c->ledger());
    for (Projection projection : {Projection::Orthographic, Projection::Perspective}) {
      Camera cam = test::orbitCamera(v.extent(), 30, 20);
      cam.projection = projection;
      const Image ref = renderReference(v, tf, cam, s, 96, 96);
      double db[2] = {0.0, 0.0};
      int planes = 0;
      for (int slab : {1, 0}) {
        render::Slice3DRenderer r(*c, v, *mosaic, limits.halfFloatRenderTargets);
        ASSERT_EQ(r.accumulationFormat(), "RGBA8");
        r.setTransferFunction(tf);
        r.setSlabSamples(slab);
        db[slab == 0 ? 1 : 0] = psnr(r.render(cam, s, 96, 96), ref);
        planes = r.sliceCountFor(s);
        if (slab == 0) {
          EXPECT_EQ(r.slabSamplesFor(s), render::Slice3DRenderer::kRgba8SlabSamples);
          EXPECT_TRUE(r.ditherFor(s));
          EXPECT_NE(r.report().note.find("slabs of"), std::string::npos) << r.report().note;
        }
      }
      std::printf(
          "  [measured] slice3d RGBA8 %s, %d planes: %.2f dB in slabs of %d, %.2f dB one plane "
          "a slice\n",
          projection == Projection::Perspective ? "perspective" : "orthographic", planes, db[1],
          render::Slice3DRenderer::kRgba8SlabSamples, db[0]);
      EXPECT_GE(db[1], 40.0);
    }
  }
  c.reset();
  test::gpuContext();
}

// Slabs take the same planes as single slices: on a half-float target the
// slabs' frame equals the one-plane-a-slice frame up to half-float rounding,
// for any slab length that does or does not divide the plane count, and MIP
// takes no slabs.
TEST(Slice3D, SlabsSampleTheSamePlanesAsSingleSlices) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSheppLogan({30, 36, 26});
  auto t3d = layout::Texture3DLayout::create(v, gpu::DeviceLimits::of(c.caps()), c.ledger());
  render::Slice3DRenderer r(c, v, *t3d);
  r.setTransferFunction(visibleTf());
  RenderSettings s = halfVoxel();
  for (Projection projection : {Projection::Orthographic, Projection::Perspective}) {
    Camera cam = obliqueCamera(v);
    cam.projection = projection;
    r.setSlabSamples(1);
    const Image single = r.render(cam, s, 64, 64);
    for (int slab : {4, 7}) {
      r.setSlabSamples(slab);
      const double db = psnr(r.render(cam, s, 64, 64), single);
      std::printf("  [measured] slice3d slabs of %d vs single slices (%s): %.2f dB\n", slab,
                  projection == Projection::Perspective ? "perspective" : "orthographic", db);
      EXPECT_GE(db, 50.0) << slab;
    }
  }
  s.mode = RenderMode::Mip;
  EXPECT_EQ(r.slabSamplesFor(s), 1);
  EXPECT_THROW(r.setSlabSamples(render::Slice3DRenderer::kMaxSlabSamples + 1), InputError);
}
