// GPU ray caster against the CPU reference on llvmpipe (DESIGN.md, Testing).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

#include "support/GpuTestContext.h"
#include "support/TestCameras.h"
#include "support/TestTransferFunctions.h"
#include "support/Texture3DCaster.h"
#include "tessera/core/Camera.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/Raycaster.h"

using namespace tessera;

namespace {

gpu::GlContext& context() {
  return test::gpuContext();
}

struct Comparison {
  double psnr;
  double ssim;
};

Comparison compare(const Volume& v, const TransferFunction& tf, Camera cam, const RenderSettings& s,
                   int size, int skipBlock = 8) {
  gpu::GlContext& c = context();
  auto layout = layout::Texture3DLayout::create(v, gpu::DeviceLimits::of(c.caps()), c.ledger());
  render::Raycaster caster(c, v, *layout);
  caster.setSkipBlockSize(skipBlock);
  caster.setTransferFunction(tf);
  cam.frame(v.extent());
  const Image gpuImage = caster.render(cam, s, size, size);
  const Image ref = renderReference(v, tf, cam, s, size, size);
  // Guard against vacuous agreement: the view must show a real image.
  int lit = 0;
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x)
      lit += ref.pixel(x, y)[0] + ref.pixel(x, y)[1] + ref.pixel(x, y)[2] > 30;
  }
  EXPECT_GT(lit, size * size / 20) << "reference image is (nearly) empty";
  const Comparison result{psnr(gpuImage, ref), ssim(gpuImage, ref)};
  std::printf("  [measured] GPU vs reference %dx%d: PSNR %.2f dB, SSIM %.5f\n", size, size,
              result.psnr, result.ssim);
  return result;
}

using test::visibleTf;

const char* kCh2 = "/usr/share/mricron/templates/ch2.nii.gz";

}  // namespace

TEST(Raycaster, PhantomCompositeMatchesReference) {
  const Volume v = makeSheppLogan({64, 64, 64});
  Camera cam;
  cam.azimuthDeg = 30;
  cam.elevationDeg = 20;
  RenderSettings s;
  const Comparison r = compare(v, visibleTf(), cam, s, 128);
  EXPECT_GE(r.psnr, 40.0);
  EXPECT_GE(r.ssim, 0.98);
}

TEST(Raycaster, PhantomMipMatchesReference) {
  const Volume v = makeSheppLogan({64, 64, 64});
  Camera cam;
  cam.azimuthDeg = -40;
  cam.elevationDeg = 10;
  RenderSettings s;
  s.mode = RenderMode::Mip;
  const Comparison r = compare(v, TransferFunction::preset("grey"), cam, s, 128);
  EXPECT_GE(r.psnr, 40.0);
}

TEST(Raycaster, OrthographicJitteredMatchesReference) {
  const Volume v = makeSphere({48, 40, 56});
  Camera cam;
  cam.projection = Projection::Orthographic;
  cam.azimuthDeg = 75;
  RenderSettings s;
  s.jitter = true;
  s.stepVoxels = 1.0;
  const Comparison r = compare(v, visibleTf(), cam, s, 96);
  EXPECT_GE(r.psnr, 40.0);
}

TEST(Raycaster, EmptySpaceSkippingDoesNotChangeTheImage) {
  const Volume v = makeSheppLogan({64, 64, 64});
  gpu::GlContext& c = context();
  test::Texture3DCaster t3d(c, v, TransferFunction::preset("bench"));
  render::Raycaster& caster = t3d.caster;
  Camera cam = test::orbitCamera(v.extent(), 20, 0);
  for (RenderMode mode : {RenderMode::Composite, RenderMode::Mip}) {
    RenderSettings s;
    s.mode = mode;
    caster.setSkipBlockSize(0);
    const Image plain = caster.render(cam, s, 96, 96);
    caster.setSkipBlockSize(4);
    const Image skipped = caster.render(cam, s, 96, 96);
    // Skipping only jumps over samples that are transparent (or below the
    // running maximum), so the images agree up to float rounding.
    EXPECT_GE(psnr(plain, skipped), 55.0) << (mode == RenderMode::Mip ? "mip" : "composite");
  }
}

TEST(Raycaster, U16AndFloatVolumesMatchReference) {
  Volume v16 = Volume::allocate({40, 40, 40}, ScalarType::U16);
  Volume vf = makeMarschnerLobb({41, 41, 41});
  const Volume sl = makeSheppLogan({40, 40, 40});
  for (std::size_t i = 0; i < v16.voxelCount(); ++i)
    v16.setValueAtIndex(i, sl.valueAtIndex(i) * 200.0 + 1000.0);
  Camera cam;
  cam.azimuthDeg = 10;
  cam.elevationDeg = 30;
  RenderSettings s;
  EXPECT_GE(compare(v16, visibleTf(), cam, s, 96).psnr, 40.0);
  EXPECT_GE(compare(vf, visibleTf(), cam, s, 96).psnr, 40.0);
}

TEST(Raycaster, Ch2CompositeAndMipMatchReference) {
  if (!std::filesystem::exists(kCh2)) GTEST_SKIP() << "mricron-data not installed";
  const Volume v = readVolume(kCh2);
  Camera cam;
  cam.azimuthDeg = 30;
  cam.elevationDeg = 15;
  RenderSettings s;
  const Comparison comp = compare(v, TransferFunction::preset("mr-default"), cam, s, 128);
  EXPECT_GE(comp.psnr, 40.0);
  s.mode = RenderMode::Mip;
  const Comparison mip = compare(v, TransferFunction::preset("grey"), cam, s, 128);
  EXPECT_GE(mip.psnr, 40.0);
}

TEST(Raycaster, ValueWindowChangesClassificationLikeReference) {
  Volume v = makeSheppLogan({48, 48, 48});
  v.setWindow({50.0, 200.0});
  Camera cam;
  cam.azimuthDeg = 45;
  RenderSettings s;
  s.opacityScale = 3.0;
  EXPECT_GE(compare(v, visibleTf(), cam, s, 96).psnr, 40.0);
}

TEST(Raycaster, ComparisonDetectsASmallCameraError) {
  // The 40 dB threshold must catch real mistakes: the same volume seen 3
  // degrees off, or with opacities 30 % off, falls below it.
  const Volume v = makeSheppLogan({64, 64, 64});
  gpu::GlContext& c = context();
  test::Texture3DCaster t3d(c, v, visibleTf());
  render::Raycaster& caster = t3d.caster;
  Camera cam = test::orbitCamera(v.extent(), 30, 0);
  RenderSettings s;
  const Image gpuImage = caster.render(cam, s, 128, 128);
  Camera off = cam;
  off.azimuthDeg += 3;
  EXPECT_LT(psnr(gpuImage, renderReference(v, visibleTf(), off, s, 128, 128)), 35.0);
  RenderSettings denser = s;
  denser.opacityScale = 1.3;
  EXPECT_LT(psnr(gpuImage, renderReference(v, visibleTf(), cam, denser, 128, 128)), 40.0);
}

// Missing data (NaN) is read as the bottom of the value range by the layouts
// and the reference alike, so it is transparent and both paths agree; the
// range is shifted away from 0 so that "NaN as raw 0" would show.
TEST(Raycaster, NanVoxelsAreTransparentLikeTheReference) {
  const Volume phantom = makeSheppLogan({48, 48, 48});
  Volume v = Volume::allocate(phantom.dims(), ScalarType::F32, "phantom with NaN");
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::size_t nan = 0;
  for (std::size_t i = 0; i < phantom.voxelCount(); ++i) {
    const bool missing = u(rng) < 0.14;
    nan += missing;
    v.setValueAtIndex(i, missing ? std::nan("") : 500.0 + 1000.0 * phantom.valueAtIndex(i));
  }
  ASSERT_EQ(v.nonFiniteCount(), nan);
  Camera cam;
  cam.azimuthDeg = 30;
  cam.elevationDeg = 20;
  const Comparison r = compare(v, visibleTf(), cam, RenderSettings{}, 128);
  EXPECT_GE(r.psnr, 55.0);
}

// Previews and full frames alternate, a preview's size following its
// quality controller: the full frame's target and the previews' are kept
// (each preview at most a sixteenth of the full frame's pixels, together
// at most a sixteenth more), the most recent first, and drawn into again
// with the same images; a size that is neither lets the others go.
TEST(Raycaster, PreviewTargetsAreKeptBesideTheFullFramesAndDrawnIntoAgain) {
  gpu::GlContext& c = context();
  const Volume v = makeSheppLogan({32, 32, 32});
  auto layout = layout::Texture3DLayout::create(v, gpu::DeviceLimits::of(c.caps()), c.ledger());
  render::Raycaster caster(c, v, *layout);
  caster.setTransferFunction(visibleTf());
  Camera cam;
  cam.azimuthDeg = 30;
  cam.elevationDeg = 20;
  cam.frame(v.extent());
  const RenderSettings s;
  const auto rgba8 = [](long long pixels) { return static_cast<std::uint64_t>(4 * pixels); };

  const Image full = caster.render(cam, s, 128, 128);
  const std::uint64_t base = caster.ownTextureBytes();  // the tables and the 128x128 target
  const Image preview16 = caster.render(cam, s, 16, 16);
  caster.render(cam, s, 17, 17);
  caster.render(cam, s, 18, 18);
  const Image again16 = caster.render(cam, s, 16, 16);
  const Image fullAgain = caster.render(cam, s, 128, 128);
  EXPECT_EQ(caster.ownTextureBytes(), base + rgba8(16 * 16 + 17 * 17 + 18 * 18))
      << "the full frame's target and three previews' held";
  EXPECT_EQ(again16.rgba(), preview16.rgba()) << "a preview's target drawn into again";
  EXPECT_EQ(fullAgain.rgba(), full.rgba()) << "the full frame's target drawn into again";

  // A fourth preview would hold more than a sixteenth: the least recently
  // used (17x17) is let go.
  caster.render(cam, s, 19, 19);
  EXPECT_EQ(caster.ownTextureBytes(), base + rgba8(19 * 19 + 16 * 16 + 18 * 18));
  // 64x64 is more than a sixteenth of 128x128, not a preview of it: the
  // 128x128 target is let go, and of the previews only 16x16 (a sixteenth
  // of 64x64) is kept, as 64x64's.
  caster.render(cam, s, 64, 64);
  EXPECT_EQ(caster.ownTextureBytes(), base - rgba8(128 * 128) + rgba8(64 * 64 + 16 * 16));
}
