// Blinn-Phong shading: every technique on every layout,
// in ES 3.0 and ES 2.0 contexts, against the shaded CPU reference; the
// gradient of a linear ramp lights the analytic normal.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include <glm/geometric.hpp>

#include "support/EachApi.h"
#include "support/GpuTestContext.h"
#include "support/TestCameras.h"
#include "support/TestLayouts.h"
#include "support/TestTransferFunctions.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/reference/VoxelGradients.h"
#include "tessera/render/Raycaster.h"
#include "tessera/render/ShadingGradient.h"
#include "tessera/render/Slice2DRenderer.h"
#include "tessera/render/Slice3DRenderer.h"

using namespace tessera;

namespace {

using test::layoutsFor;
using test::visibleTf;

// Slicing cannot stop early; the ray caster and the reference are told the same.
RenderSettings shadedSettings() {
  RenderSettings s;
  s.stepVoxels = 0.5;
  s.ertThreshold = 1.0;
  s.shading.enabled = true;
  return s;
}

Camera obliqueCamera(const Volume& v) {
  return test::orbitCamera(v.extent(), 35, 25);
}

Image raycastWith(gpu::GlContext& c, const Volume& v, const layout::Layout& l, const Camera& cam,
                  const RenderSettings& s, int size,
                  layout::GradientWish gradient = layout::GradientWish::OnTheFly) {
  render::Raycaster caster(c, v, l);
  caster.setTransferFunction(visibleTf());
  caster.setGradient(gradient);
  return caster.render(cam, s, size, size);
}

Image sliceWith(gpu::GlContext& c, const Volume& v, const layout::Layout& l, const Camera& cam,
                const RenderSettings& s, int size,
                layout::GradientWish gradient = layout::GradientWish::OnTheFly) {
  render::Slice3DRenderer slicer(c, v, l);
  slicer.setTransferFunction(visibleTf());
  slicer.setGradient(gradient);
  return slicer.render(cam, s, size, size);
}

// `sliceBar`: view-aligned slices sample other positions than rays, which
// shows at the phantom's ideal steps (where normals turn within a voxel).
// slice3d accumulates in half floats where the context renders to them (ES 2:
// EXT_color_buffer_half_float, which Mesa has); in RGBA8 the phantom fell to
// 38.7 dB, so a context without them is held to 35 dB.
void expectShadedLayoutsMatchReference(gpu::ApiLevel api, const Volume& v, double sliceBar) {
  test::withApi(api, [&](gpu::GlContext& c) {
    if (!gpu::DeviceLimits::of(c.caps()).halfFloatRenderTargets) {
      std::printf("  [note] no half-float render target: slice3d accumulates in RGBA8\n");
      sliceBar = std::min(sliceBar, 35.0);
    }
    const Camera cam = obliqueCamera(v);
    const RenderSettings s = shadedSettings();
    RenderSettings unshaded = s;
    unshaded.shading.enabled = false;
    const Image ref = renderReference(v, visibleTf(), cam, s, 96, 96);
    const Image refUnshaded = renderReference(v, visibleTf(), cam, unshaded, 96, 96);
    ASSERT_LT(psnr(ref, refUnshaded), 30.0) << "shading must change the image";
    // The precomputed gradient (ES 3: an RGBA8 3D texture) against the
    // reference of the same quantised field, and against the exact one.
    const VoxelGradients gradients = computeVoxelGradients(v);
    const TrilinearReconstruction values(v);
    const Image refPre = renderReference(v, VoxelGradientReconstruction(values, gradients),
                                         visibleTf(), cam, s, 96, 96);
    const char* name = v.dims().x == 37 ? "sphere" : "phantom";
    for (const auto& l : layoutsFor(c, v)) {
      if (gpu::DeviceLimits::of(c.caps()).halfFloatRenderTargets) {
        render::Slice3DRenderer slicer(c, v, *l);
        EXPECT_NE(slicer.accumulationFormat().find("RGBA16F"), std::string::npos)
            << slicer.accumulationFormat();
      }
      const double cast = psnr(raycastWith(c, v, *l, cam, s, 96), ref);
      const double slice = psnr(sliceWith(c, v, *l, cam, s, 96), ref);
      std::printf(
          "  [measured] shaded %-7s %s %-13s raycast %.2f dB, slice3d %.2f dB vs reference\n", name,
          test::apiName(api), l->name().c_str(), cast, slice);
      EXPECT_GE(cast, 40.0) << l->name();
      EXPECT_GE(slice, sliceBar) << l->name();
      if (api != gpu::ApiLevel::Gles3) continue;
      const Image pre = raycastWith(c, v, *l, cam, s, 96, layout::GradientWish::Precomputed);
      const double same = psnr(pre, refPre);
      const double exact = psnr(pre, ref);
      const double slicePre =
          psnr(sliceWith(c, v, *l, cam, s, 96, layout::GradientWish::Precomputed), refPre);
      std::printf(
          "  [measured] shaded %-7s %s %-13s precomputed gradient: raycast %.2f dB vs its "
          "reference, %.2f dB vs the exact-gradient reference (quantisation: %.2f dB); "
          "slice3d %.2f dB vs its reference\n",
          name, test::apiName(api), l->name().c_str(), same, exact, psnr(refPre, ref), slicePre);
      EXPECT_GE(same, 40.0) << l->name();
      EXPECT_GE(exact, 40.0) << l->name();
      EXPECT_GE(slicePre, sliceBar) << l->name();
    }
  });
}

}  // namespace

using ShadingOnEachApi = test::EachApi;
INSTANTIATE_TEST_SUITE_P(Api, ShadingOnEachApi, test::kEveryApi, test::apiParamName);

// A smooth field (the sphere's radial ramp) and sharp steps (the phantom).
TEST_P(ShadingOnEachApi, EveryLayoutMatchesShadedReference) {
  expectShadedLayoutsMatchReference(GetParam(), makeSphere({37, 53, 29}), 40.0);
  expectShadedLayoutsMatchReference(GetParam(), makeSheppLogan({38, 53, 29}), 40.0);
}

namespace {

// f = 8 i + 5 j (u8): its gradient is (8, 5, 0) raw units per voxel
// everywhere, exactly what central differences give a voxel or more from
// the x and y faces (z: f does not change, clamping or not).
Volume rampVolume() {
  Volume v = Volume::allocate({16, 16, 8}, ScalarType::U8, "ramp");
  for (int z = 0; z < 8; ++z) {
    for (int y = 0; y < 16; ++y) {
      for (int x = 0; x < 16; ++x) v.setValueAtIndex(v.index(x, y, z), 8.0 * x + 5.0 * y);
    }
  }
  v.invalidateRange();
  return v;
}

// Every interior pixel of a top view of the ramp through an opaque grey TF
// (the first sample is the pixel) against Blinn-Phong of the analytic normal.
void expectRampLitByAnalyticNormal(const Image& img, const Volume& v, const Camera& cam,
                                   const RenderSettings& s, const char* what) {
  const glm::dvec3 g = glm::dvec3(8.0, 5.0, 0.0) / v.window().width();
  const ShadingLight light = shadingLight(s.shading, cam.basis()[2], cam.modelFromWorld);
  const double expected = shadeBlinnPhong(glm::dvec3(0.5), g, s.shading, light).x;
  ASSERT_GT(std::abs(expected - 0.5) * 255.0, 10.0) << "the light must show against unlit grey";
  int checked = 0, worst = 0;
  for (int py = 0; py < img.height(); ++py) {
    for (int px = 0; px < img.width(); ++px) {
      const Ray ray = cam.pixelRay(px, py, img.width(), img.height());
      const glm::dvec3 extent = v.extent();
      // The top face (z = +extent/2) in voxel units.
      const double t = (extent.z / 2 - ray.origin.z) / ray.direction.z;
      const glm::dvec3 voxel = (ray.origin + t * ray.direction) / extent + 0.5;
      const glm::dvec3 i = voxel * glm::dvec3(v.dims()) - 0.5;
      if (i.x < 1.5 || i.y < 1.5 || i.x > 12.5 || i.y > 12.5) continue;
      ++checked;
      worst = std::max(
          worst, std::abs(img.pixel(px, py)[0] - static_cast<int>(std::lround(expected * 255.0))));
    }
  }
  std::printf("  [measured] ramp %s: %d interior pixels, worst %d/255 from the analytic light\n",
              what, checked, worst);
  EXPECT_GT(checked, 1000);
  EXPECT_LE(worst, 2) << what;
}

}  // namespace

// 8-bit voxels ride in the precomputed gradient's alpha: a lit sample's value
// and gradient come from one fetch (render/sample.glsl: post-classified and
// slice3d samples) where the layout stores raw / 255, and a pre-integrated
// segment's end values come from that texture too; 16-bit volumes read the
// layout.
TEST(Shading, EightBitLitSamplesTakeTheirValueFromTheGradientFetch) {
  test::withApi(gpu::ApiLevel::Gles3, [](gpu::GlContext& c) {
    const Volume v8 = makeSphere({37, 53, 29});
    ASSERT_EQ(v8.type(), ScalarType::U8);
    Volume v16 = Volume::allocate(v8.dims(), ScalarType::U16);
    for (std::size_t i = 0; i < v8.voxelCount(); ++i) v16.setValueAtIndex(i, v8.valueAtIndex(i));
    const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
    const Camera cam = obliqueCamera(v8);
    RenderSettings post = shadedSettings();
    RenderSettings pre = post;
    pre.sampling = defaultSampling();
    pre.stepVoxels = 1.0;
    for (const RenderSettings& s : {post, pre}) {
      const auto l8 = layout::Texture3DLayout::create(v8, limits, c.ledger());
      const auto l16 = layout::Texture3DLayout::create(v16, limits, c.ledger());
      render::ShadingGradient g8(c, v8, *l8, 1), g16(c, v16, *l16, 1);
      g8.setWish(layout::GradientWish::Precomputed);
      g16.setWish(layout::GradientWish::Precomputed);
      g8.prepare(s);
      g16.prepare(s);
      EXPECT_TRUE(g8.valuesFromGradient(s));
      EXPECT_FALSE(g16.valuesFromGradient(s)) << "16-bit values do not fit the alpha";
      RenderSettings unlit = s;
      unlit.shading.enabled = false;
      EXPECT_FALSE(g8.valuesFromGradient(unlit)) << "unlit samples read the layout";

      // The image: against the reference of the same field (values from the
      // voxels, the quantised gradient), and against the 16-bit volume's
      // (two fetches per lit sample).
      const VoxelGradients gradients = computeVoxelGradients(v8);
      const TrilinearReconstruction values(v8);
      const Image ref = renderReference(v8, VoxelGradientReconstruction(values, gradients),
                                        visibleTf(), cam, s, 96, 96);
      const Image fused = raycastWith(c, v8, *l8, cam, s, 96, layout::GradientWish::Precomputed);
      const Image two = raycastWith(c, v16, *l16, cam, s, 96, layout::GradientWish::Precomputed);
      const double vsRef = psnr(fused, ref);
      const double vsTwo = psnr(fused, two);
      std::printf("  [measured] %s: 8-bit %.2f dB vs its reference, %.2f dB vs 16-bit\n",
                  s.sampling.preintegrate ? "pre-integrated" : "post-classified", vsRef, vsTwo);
      EXPECT_GE(vsRef, 40.0);
      EXPECT_GE(vsTwo, 40.0);
    }
  });
}

TEST(Shading, LinearRampIsLitByItsAnalyticNormal) {
  const Volume v = rampVolume();
  const Camera cam = test::topDownOrthographic(v.extent());  // looking down -z
  const TransferFunction opaqueGrey = test::oneColorTf({0.5, 0.5, 0.5}, {{0.0, 1.0}, {1.0, 1.0}});
  RenderSettings s;
  s.shading.enabled = true;
  s.shading.headlight = false;
  s.shading.lightDirection = {1.0, 2.0, 3.0};
  s.shading.shininess = 8.0;
  expectRampLitByAnalyticNormal(renderReference(v, opaqueGrey, cam, s, 96, 96), v, cam, s,
                                "reference");
  for (gpu::ApiLevel api : {gpu::ApiLevel::Gles3, gpu::ApiLevel::Gles2}) {
    test::withApi(api, [&](gpu::GlContext& c) {
      for (const auto& l : layoutsFor(c, v)) {
        render::Raycaster caster(c, v, *l);
        caster.setTransferFunction(opaqueGrey);
        caster.setGradient(layout::GradientWish::OnTheFly);
        const std::string what = std::string("raycast ") + test::apiName(api) + " " + l->name();
        expectRampLitByAnalyticNormal(caster.render(cam, s, 96, 96), v, cam, s, what.c_str());
        if (api != gpu::ApiLevel::Gles3) continue;
        // The ramp's differences (8, 5, 0) quantise exactly (codes 127, 127, 0).
        caster.setGradient(layout::GradientWish::Precomputed);
        expectRampLitByAnalyticNormal(caster.render(cam, s, 96, 96), v, cam, s,
                                      (what + ", precomputed gradient").c_str());
      }
    });
  }
}

// slice2d keeps its own stacks (no layout): its planes are the voxel planes,
// which are the reference's samples for an orthographic view along a stack
// axis at a 1-voxel step; its gradient comes from each slice's neighbours.
TEST(Shading, Slice2DMatchesShadedReferenceAlongEachStackOnEs3AndEs2) {
  const Volume v = makeSphere({37, 53, 29});  // isotropic: the planes are 1-voxel steps
  RenderSettings s = shadedSettings();
  s.stepVoxels = 1.0;
  // A fixed light off every axis: a gradient component on the wrong axis shows.
  s.shading.headlight = false;
  s.shading.lightDirection = {1.0, 2.0, 3.0};
  for (gpu::ApiLevel api : {gpu::ApiLevel::Gles3, gpu::ApiLevel::Gles2}) {
    test::withApi(api, [&](gpu::GlContext& c) {
      render::Slice2DRenderer slicer(c, v, {});
      slicer.setTransferFunction(visibleTf());
      for (int axis = 0; axis < 3; ++axis) {
        const Camera cam = test::axisCamera(v.extent(), axis, Projection::Orthographic);
        const Image img = slicer.render(cam, s, 96, 96);
        ASSERT_EQ(slicer.lastStackAxis(), axis);
        const double db = psnr(img, renderReference(v, visibleTf(), cam, s, 96, 96));
        std::printf("  [measured] shaded sphere  %s slice2d stack %c: %.2f dB vs reference\n",
                    test::apiName(api), "xyz"[axis], db);
        EXPECT_GE(db, 40.0) << test::apiName(api) << " axis " << axis;
      }
      RenderSettings unshaded = s;
      unshaded.shading.enabled = false;
      Camera cam;
      cam.projection = Projection::Orthographic;
      cam.frame(v.extent());
      EXPECT_GE(psnr(slicer.render(cam, unshaded, 96, 96),
                     renderReference(v, visibleTf(), cam, unshaded, 96, 96)),
                40.0)
          << "back to unshaded stacks";
    });
  }
}

TEST(Shading, Slice2DAsksForPostClassification) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSphere({16, 16, 16});
  render::Slice2DRenderer slicer(c, v, {.classification = render::SliceClassification::Pre});
  Camera cam;
  cam.frame(v.extent());
  try {
    slicer.render(cam, shadedSettings(), 32, 32);
    FAIL() << "pre-classified slices cannot be shaded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--classify post"), std::string::npos) << e.what();
  }
}

// Gradient-magnitude opacity modulation (Shading::gradientOpacity): every
// technique against the reference on ES 3 and ES 2, lit and unlit.
TEST(Shading, GradientOpacityMatchesTheReferenceForEveryTechnique) {
  const Volume v = makeSheppLogan({38, 53, 29});
  for (gpu::ApiLevel api : {gpu::ApiLevel::Gles3, gpu::ApiLevel::Gles2}) {
    test::withApi(api, [&](gpu::GlContext& c) {
      const Camera cam = obliqueCamera(v);
      for (bool lit : {true, false}) {
        RenderSettings s = shadedSettings();
        s.shading.enabled = lit;
        s.shading.gradientOpacity = true;
        s.shading.gradientLow = 0.05;  // strong: the phantom's flat regions fade
        s.shading.gradientHigh = 0.25;
        const Image ref = renderReference(v, visibleTf(), cam, s, 96, 96);
        RenderSettings plain = s;
        plain.shading.gradientOpacity = false;
        ASSERT_LT(psnr(ref, renderReference(v, visibleTf(), cam, plain, 96, 96)), 35.0)
            << "the modulation must change the image";
        for (const auto& l : layoutsFor(c, v)) {
          const double cast = psnr(raycastWith(c, v, *l, cam, s, 96), ref);
          const double slice = psnr(sliceWith(c, v, *l, cam, s, 96), ref);
          std::printf(
              "  [measured] gradient opacity %s %s %-13s raycast %.2f dB, slice3d %.2f dB\n",
              lit ? "lit  " : "unlit", test::apiName(api), l->name().c_str(), cast, slice);
          EXPECT_GE(cast, 40.0) << l->name();
          EXPECT_GE(slice, 40.0) << l->name();
        }
        // slice2d along its stack at a 1-voxel step: its planes are the reference's samples.
        Camera ortho;
        ortho.projection = Projection::Orthographic;
        ortho.frame(v.extent());
        RenderSettings s1 = s;
        s1.stepVoxels = 1.0;
        render::Slice2DRenderer slicer(c, v, {});
        slicer.setTransferFunction(visibleTf());
        const double db = psnr(slicer.render(ortho, s1, 96, 96),
                               renderReference(v, visibleTf(), ortho, s1, 96, 96));
        std::printf("  [measured] gradient opacity %s %s slice2d %.2f dB\n",
                    lit ? "lit  " : "unlit", test::apiName(api), db);
        EXPECT_GE(db, 40.0);
      }
    });
  }
}

// A homogeneous cube (value 200 in 0) seen through its middle: without the
// modulation its whole depth is opaque-ish; with it only the two faces,
// where the gradient is large, keep their opacity.
TEST(Shading, GradientOpacityClearsHomogeneousInteriorsAndKeepsBoundaries) {
  Volume v = Volume::allocate({32, 32, 32}, ScalarType::U8);
  auto* d = reinterpret_cast<std::uint8_t*>(v.bytes().data());
  for (int z = 0; z < 32; ++z) {
    for (int y = 0; y < 32; ++y) {
      for (int x = 0; x < 32; ++x) {
        const bool inside = x >= 6 && x < 26 && y >= 6 && y < 26 && z >= 6 && z < 26;
        d[static_cast<std::size_t>((z * 32 + y) * 32 + x)] = inside ? 200 : 0;
      }
    }
  }
  v.setWindow({0.0, 255.0});
  const TransferFunction tf =
      test::oneColorTf({1.0, 1.0, 1.0}, {{0.0, 0.0}, {0.5, 0.15}, {1.0, 0.15}});
  Camera cam;
  cam.projection = Projection::Orthographic;
  cam.frame(v.extent());
  RenderSettings s;
  s.stepVoxels = 0.5;
  s.background = {0.0, 0.0, 0.0, 1.0};
  RenderSettings mod = s;
  mod.shading.gradientOpacity = true;
  const auto centre = [](const Image& img) { return img.pixel(32, 32)[0] / 255.0; };
  const double plainRef = centre(renderReference(v, tf, cam, s, 64, 64));
  const double modRef = centre(renderReference(v, tf, cam, mod, 64, 64));
  // The two faces alone: 1 - (1 - a)^(shell), a shell of about 2 voxels each.
  std::printf("  [measured] cube centre: %.3f plain, %.3f modulated (reference)\n", plainRef,
              modRef);
  EXPECT_GT(plainRef, 0.9);
  EXPECT_LT(modRef, 0.6 * plainRef) << "the interior fades";
  EXPECT_GT(modRef, 0.15) << "the faces keep their opacity";
  // A ray beside the cube sees nothing either way; the GPU agrees.
  test::withApi(gpu::ApiLevel::Gles3, [&](gpu::GlContext& c) {
    const auto layouts = layoutsFor(c, v);
    render::Raycaster caster(c, v, *layouts.front());
    caster.setTransferFunction(tf);
    const Image gpuMod = caster.render(cam, mod, 64, 64);
    std::printf("  [measured] cube centre on the GPU: %.3f modulated\n", centre(gpuMod));
    EXPECT_NEAR(centre(gpuMod), modRef, 2.0 / 255.0);
    EXPECT_EQ(gpuMod.pixel(2, 2)[0], 0);
  });
}
