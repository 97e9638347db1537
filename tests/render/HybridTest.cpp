// Hybrid low/high-resolution rendering (Moser & Weiskopf 2008, section 4):
// upscaled low-resolution volume vs full resolution, and each line-attenuation
// method vs the full-resolution ground truth with correct line occlusion.
#include <gtest/gtest.h>

#include <cstdio>
#include <map>

#include "support/GpuTestContext.h"
#include "support/TestTransferFunctions.h"
#include "tessera/core/Error.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/MosaicLayout.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceOverlay.h"
#include "tessera/render/HybridCompositor.h"
#include "tessera/render/Raycaster.h"
#include "tessera/render/Slice2DRenderer.h"
#include "tessera/render/Slice3DRenderer.h"
#include "tessera/render/SliceProjection.h"

using namespace tessera;
using render::HybridOptions;
using render::OffscreenSize;
using render::OverlayOpacity;

namespace {

// Saturated hues, semi-transparent: the case where luminance says little
// about opacity (dark blue is opaque, pale yellow less so).
TransferFunction colouredTf() {
  return test::tfFromPoints({{0.0, {0.0, 0.0, 0.0}},
                             {0.2, {0.1, 0.1, 0.8}},
                             {0.5, {0.9, 0.2, 0.1}},
                             {1.0, {1.0, 0.95, 0.4}}},
                            {{0.02, 0.0}, {0.15, 0.06}, {0.5, 0.12}, {1.0, 0.35}});
}

struct Scene {
  Volume volume = makeSheppLogan({64, 64, 64});
  TransferFunction tf = colouredTf();
  Camera camera;
  RenderSettings settings;
  std::unique_ptr<layout::Layout> layout;
  std::unique_ptr<render::Raycaster> caster;
  std::unique_ptr<render::HybridCompositor> compositor;

  explicit Scene(gpu::GlContext& c) {
    camera.frame(volume.extent());
    camera.azimuthDeg = 30;
    camera.elevationDeg = 20;
    layout = layout::Texture3DLayout::create(volume, gpu::DeviceLimits::of(c.caps()), c.ledger());
    caster = std::make_unique<render::Raycaster>(c, volume, *layout);
    caster->setTransferFunction(tf);
    compositor = std::make_unique<render::HybridCompositor>(c);
  }
  Image hybrid(int w, int h, OffscreenSize size, OverlayOpacity method) {
    compositor->render(*caster, camera, settings, volume.extent(), w, h, {size, method});
    return compositor->readImage();
  }
};

int litPixels(const Image& img) {
  int lit = 0;
  for (int y = 0; y < img.height(); ++y) {
    for (int x = 0; x < img.width(); ++x) {
      const std::uint8_t* p = img.pixel(x, y);
      lit += p[0] + p[1] + p[2] > 30;
    }
  }
  return lit;
}

}  // namespace

TEST(Hybrid, ParsesOffscreenSizesAndMethods) {
  EXPECT_EQ(OffscreenSize::parse("256x512").resolve(480, 640), glm::ivec2(256, 512));
  EXPECT_EQ(OffscreenSize::parse("0.25").resolve(480, 640), glm::ivec2(120, 160));
  EXPECT_EQ(OffscreenSize::parse("full").resolve(480, 640), glm::ivec2(480, 640));
  EXPECT_THROW(OffscreenSize::parse("1.5"), InputError);
  EXPECT_THROW(OffscreenSize::parse("0x128"), InputError);
  EXPECT_THROW(OffscreenSize::parse("big"), InputError);
  for (OverlayOpacity m : render::allOverlayOpacities())
    EXPECT_EQ(render::parseOverlayOpacity(render::overlayOpacityName(m)), m);
  EXPECT_THROW(render::parseOverlayOpacity("depth"), InputError);
}

// Without lines, offscreen = screen reproduces the ray caster's image exactly
// (compositing over black adds nothing), and the upscaled low-resolution
// image stays close to full resolution: volume rendering has little energy
// at the highest image frequencies (the paper's premise).
TEST(Hybrid, UpscaledLowResolutionIsCloseToFullResolution) {
  gpu::GlContext& c = test::gpuContext();
  Scene scene(c);
  const int w = 256, h = 192;
  const Image full = scene.caster->render(scene.camera, scene.settings, w, h);
  ASSERT_GT(litPixels(full), w * h / 16);
  const Image same = scene.hybrid(w, h, OffscreenSize::ofFactor(1.0), OverlayOpacity::Alpha);
  EXPECT_TRUE(std::isinf(psnr(same, full))) << psnr(same, full);

  const double half =
      psnr(scene.hybrid(w, h, OffscreenSize::ofFactor(0.5), OverlayOpacity::Alpha), full);
  const double fixed128 =
      psnr(scene.hybrid(w, h, OffscreenSize::ofSize(128, 128), OverlayOpacity::Alpha), full);
  const double quarter =
      psnr(scene.hybrid(w, h, OffscreenSize::ofFactor(0.25), OverlayOpacity::Alpha), full);
  std::printf(
      "  [measured] upscaled vs full %dx%d: 128x96 %.2f dB, 128x128 (stretched) %.2f dB, "
      "64x48 %.2f dB\n",
      w, h, half, fixed128, quarter);
  // Bilinear upscaling by 2 of a smooth rendering: > 30 dB is visually close
  // (8-bit noise is ~50 dB, a 3 degree rotation scores ~20 dB here).
  EXPECT_GT(half, 30.0);
  EXPECT_GT(fixed128, 30.0);  // the 4:3 view is rendered square and stretched back
  EXPECT_GT(quarter, 25.0);
  EXPECT_GT(half, quarter);  // more pixels, closer

  // Teeth: a fixed target rendered with its own (square) aspect instead of
  // the screen's would be distorted.
  scene.caster->setViewAspect(1.0);
  const Image squareView = scene.caster->render(scene.camera, scene.settings, w, h);
  scene.caster->setViewAspect(0.0);
  EXPECT_LT(psnr(squareView, full), 25.0);
}

// Two renders over black and white give a = 1 - (C_white - C_black), the
// target's alpha up to 8-bit rounding.
TEST(Hybrid, TwoPassOpacityEqualsTheTargetAlpha) {
  gpu::GlContext& c = test::gpuContext();
  Scene scene(c);
  scene.hybrid(160, 120, OffscreenSize::ofFactor(0.5), OverlayOpacity::Alpha);
  const Image alpha = scene.compositor->readOpacityLayer();
  scene.hybrid(160, 120, OffscreenSize::ofFactor(0.5), OverlayOpacity::TwoPass);
  EXPECT_EQ(scene.compositor->timings().volumePasses, 2);
  const Image twoPass = scene.compositor->readOpacityLayer();
  ASSERT_EQ(alpha.width(), 80);
  int worst = 0, opaque = 0;
  for (std::size_t i = 0; i < alpha.rgba().size(); i += 4) {
    for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(alpha.rgba()[i + ch], twoPass.rgba()[i + ch]);
    worst = std::max(worst, std::abs(alpha.rgba()[i + 3] - twoPass.rgba()[i + 3]));
    opaque += alpha.rgba()[i + 3] > 64;
  }
  std::printf("  [measured] two-pass vs target alpha: max difference %d/255 (%d pixels > 0.25)\n",
              worst, opaque);
  EXPECT_GT(opaque, 500);
  EXPECT_LE(worst, 2);
}

// Figure 2 of the paper as numbers: each method against the full-resolution
// ground truth (CPU reference, rays terminated at the lines). All share the
// same upscaled volume, so they differ only in the line pixels.
TEST(Hybrid, OpacityMethodsAgainstGroundTruth) {
  gpu::GlContext& c = test::gpuContext();
  Scene scene(c);
  scene.compositor->setOverlayLines(
      render::overlayLines(scene.volume, render::OverlayOptions::parse("box,axes,roi")));
  const int w = 256, h = 256;
  std::map<OverlayOpacity, double> score;
  Image truth;
  for (OverlayOpacity m : render::allOverlayOpacities()) {
    const Image img = scene.hybrid(w, h, OffscreenSize::ofSize(128, 128), m);
    if (truth.width() == 0) {
      truth = renderReferenceWithLines(scene.volume, scene.tf, scene.camera, scene.settings, w, h,
                                       scene.compositor->overlays().readColor(),
                                       scene.compositor->overlays().readDistance());
    }
    score[m] = psnr(img, truth);
  }
  // Baselines: the same hybrid frame with lines pasted on top unattenuated,
  // and the volume without any lines.
  const Image lines = scene.compositor->overlays().readColor();
  const Image noAttenuation = [&] {
    Image img = scene.hybrid(w, h, OffscreenSize::ofSize(128, 128), OverlayOpacity::Alpha);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (lines.pixel(x, y)[3]) {
          std::copy_n(lines.pixel(x, y), 3, img.pixel(x, y));
          img.pixel(x, y)[3] = 255;
        }
    return img;
  }();
  const double pasted = psnr(noAttenuation, truth);
  // The same with the volume at full resolution: what upscaling costs.
  const double fullAlpha =
      psnr(scene.hybrid(w, h, OffscreenSize::ofFactor(1.0), OverlayOpacity::Alpha), truth);
  std::printf("  [measured] vs ground truth %dx%d, offscreen 128x128:", w, h);
  for (const auto& [m, p] : score)
    std::printf(" %s %.2f dB,", render::overlayOpacityName(m).c_str(), p);
  std::printf(" lines on top %.2f dB; alpha at full resolution %.2f dB\n", pasted, fullAlpha);

  // Threshold: the upscaled volume alone scores ~33 dB against full
  // resolution here; lines are ~4 % of the pixels, so a method that gets the
  // line pixels roughly right stays within a few dB of that, while pasting
  // the lines on top (the error the paper avoids) costs far more.
  for (const auto& [m, p] : score) EXPECT_GT(p, 24.0) << render::overlayOpacityName(m);
  EXPECT_GT(score[OverlayOpacity::Alpha], 29.0);
  for (const auto& [m, p] : score) EXPECT_GE(score[OverlayOpacity::Alpha], p - 0.05);
  EXPECT_GT(score[OverlayOpacity::Alpha], pasted + 3.0);
  EXPECT_GT(fullAlpha, score[OverlayOpacity::Alpha]);
}

// The same shaders in an OpenGL ES 2.0 context (GLSL ES 1.00): the devices
// the paper targets.
TEST(Hybrid, RunsInAnEs2Context) {
  gpu::GlContext::Options o;
  o.api = gpu::ApiLevel::Gles2;
  auto c = gpu::GlContext::createHeadless(o);
  const Volume v = makeSheppLogan({32, 32, 32});
  auto layout = layout::MosaicLayout::create(v, gpu::DeviceLimits::of(c->caps()), c->ledger());
  render::Raycaster caster(*c, v, *layout);
  caster.setTransferFunction(colouredTf());
  render::HybridCompositor compositor(*c);
  compositor.setOverlayLines(render::overlayLines(v, render::OverlayOptions::parse("box,axes")));
  Camera cam;
  cam.frame(v.extent());
  cam.azimuthDeg = 40;
  RenderSettings s;
  compositor.render(caster, cam, s, v.extent(), 96, 96,
                    {OffscreenSize::ofSize(48, 48), OverlayOpacity::TwoPass});
  const Image img = compositor.readImage();
  const Image truth =
      renderReferenceWithLines(v, colouredTf(), cam, s, 96, 96, compositor.overlays().readColor(),
                               compositor.overlays().readDistance());
  const double p = psnr(img, truth);
  std::printf("  [measured] ES 2.0 two-pass 48x48 -> 96x96 vs ground truth: %.2f dB\n", p);
  EXPECT_GT(litPixels(img), 96 * 96 / 10);
  EXPECT_GT(p, 22.0);
}

namespace {

// A slicer through the compositor at a 128x128 target vs its own frame at the
// screen's full resolution: it renders the target in the screen's shape with
// the requested number of pixels, and the upscaled image stays close.
template <class Slicer>
void expectSlicerPlugsIntoTheCompositor(const char* name, Scene& scene, Slicer& slicer) {
  slicer.setTransferFunction(scene.tf);
  const int w = 256, h = 192;
  const Image full = slicer.render(scene.camera, scene.settings, w, h);
  scene.compositor->render(slicer, scene.camera, scene.settings, scene.volume.extent(), w, h,
                           {OffscreenSize::ofSize(128, 128), OverlayOpacity::Alpha});
  EXPECT_EQ(scene.compositor->timings().rendered, glm::ivec2(148, 111));
  const double p = psnr(scene.compositor->readImage(), full);
  std::printf("  [measured] %s 148x111 upscaled vs full %dx%d: %.2f dB\n", name, w, h, p);
  EXPECT_GT(litPixels(full), w * h / 16);
  EXPECT_GT(p, 30.0);
}

}  // namespace

TEST(Hybrid, Slice3DPlugsIntoTheCompositor) {
  gpu::GlContext& c = test::gpuContext();
  Scene scene(c);
  render::Slice3DRenderer slicer(c, scene.volume, *scene.layout);
  expectSlicerPlugsIntoTheCompositor("slice3d", scene, slicer);
}

TEST(Hybrid, Slice2DPlugsIntoTheCompositor) {
  gpu::GlContext& c = test::gpuContext();
  Scene scene(c);
  render::Slice2DRenderer slicer(c, scene.volume, render::Slice2DOptions{});
  expectSlicerPlugsIntoTheCompositor("slice2d", scene, slicer);
}

TEST(Hybrid, SliceTargetKeepsThePixelCountInTheScreensShape) {
  EXPECT_EQ(render::sliceTargetSize(128, 128, 480.0 / 640.0), glm::ivec2(111, 148));
  EXPECT_EQ(render::sliceTargetSize(128, 128, 1024.0 / 768.0), glm::ivec2(148, 111));
  EXPECT_EQ(render::sliceTargetSize(240, 320, 480.0 / 640.0), glm::ivec2(240, 320));
}
