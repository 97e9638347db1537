// Fewer samples for the same image: pre-integrated
// classification and adaptive steps in the GPU ray caster, against the CPU
// reference that takes the same samples (>= 40 dB) and against a fine
// reference (every sample at 0.25 voxel): the quality they buy or cost.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>

#include "render/SubStepClip.h"
#include "support/GpuTestContext.h"
#include "support/TestCameras.h"
#include "support/TestTransferFunctions.h"
#include "support/Texture3DCaster.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/layout/MosaicLayout.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/Raycaster.h"

using namespace tessera;

namespace {

using test::visibleTf;

const char* kCh2 = "/usr/share/mricron/templates/ch2.nii.gz";

// A high-frequency TF: eight narrow opacity spikes (0.024 of the value range
// wide) in distinct colours; a sample misses a spike unless it lands on it.
TransferFunction spikyTf() {
  TransferFunction tf;
  tf.name = "spikes";
  const glm::dvec3 colours[] = {{1, .2, .2}, {.2, 1, .2}, {.2, .4, 1}, {1, 1, .2},
                                {1, .2, 1},  {.2, 1, 1},  {1, .6, .2}, {1, 1, 1}};
  tf.addColor(0.0, {0.0, 0.0, 0.0});
  tf.addOpacity(0.0, 0.0);
  for (int i = 0; i < 8; ++i) {
    const double c = 0.25 + 0.08 * i;
    tf.addOpacity(c - 0.012, 0.0);
    tf.addOpacity(c, 0.6);
    tf.addOpacity(c + 0.012, 0.0);
    tf.addColor(c - 0.03, colours[i]);
    tf.addColor(c + 0.03, colours[i]);
  }
  tf.addOpacity(1.0, 0.0);
  return tf;
}

RenderSettings sampling(bool pre, bool adaptive, double step = 0.5, double tolerance = 0.5) {
  RenderSettings s;
  s.stepVoxels = step;
  s.sampling.preintegrate = pre;
  s.sampling.adaptive = adaptive;
  s.sampling.tolerance = tolerance;
  s.sampling.maxMultiplier = 16;
  return s;
}

const char* name(const RenderSettings& s) {
  if (s.sampling.preintegrate && s.sampling.adaptive) return "pre+adaptive";
  if (s.sampling.preintegrate) return "pre";
  if (s.sampling.adaptive) return "adaptive";
  return "plain";
}

// The GPU image and the CPU reference walking the caster's grid.
struct Twin {
  Image gpu;
  Image cpu;
  ReferenceStats stats;
};

Twin renderTwin(render::Raycaster& caster, const Volume& v, const TransferFunction& tf,
                const Camera& cam, const RenderSettings& s, int size) {
  Twin t;
  t.gpu = caster.render(cam, s, size, size);
  const StepGrid* grid = caster.stepGrid().valid() ? &caster.stepGrid() : nullptr;
  t.cpu = renderReference(v, tf, cam, s, size, size, 0, &t.stats, nullptr, grid);
  return t;
}

Image fineReference(const Volume& v, const TransferFunction& tf, const Camera& cam,
                    RenderSettings s, int size) {
  s.stepVoxels = 0.25;
  s.sampling = Sampling();
  s.maxSteps = 65536;
  return renderReference(v, tf, cam, s, size, size);
}

Camera oblique(const Volume& v) {
  return test::orbitCamera(v, 35, 25);
}

}  // namespace

TEST(Sampling, GpuMatchesTheReferenceTakingTheSameSamplesOnEs3) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSheppLogan({48, 48, 48});
  test::Texture3DCaster t3d(c, v, visibleTf());
  render::Raycaster& caster = t3d.caster;
  const Camera cam = oblique(v);
  for (bool shade : {false, true}) {
    for (auto [pre, adaptive] : {std::pair{true, false}, {false, true}, {true, true}}) {
      RenderSettings s = sampling(pre, adaptive);
      s.shading.enabled = shade;
      const Twin t = renderTwin(caster, v, visibleTf(), cam, s, 96);
      const double db = psnr(t.gpu, t.cpu);
      std::printf("  [measured] es3 %-12s %s GPU vs its reference: %.2f dB\n", name(s),
                  shade ? "shaded  " : "unshaded", db);
      EXPECT_GE(db, 40.0) << name(s) << " shade " << shade;
    }
  }
}

TEST(Sampling, GpuMatchesTheReferenceOnEs2WithHalfAndEightBitTables) {
  const Volume v = makeSheppLogan({48, 48, 48});
  test::withApi(gpu::ApiLevel::Gles2, [&](gpu::GlContext& c) {
    auto layout = layout::MosaicLayout::create(v, gpu::DeviceLimits::of(c.caps()), c.ledger());
    render::Raycaster caster(c, v, *layout);
    caster.setTransferFunction(visibleTf());
    const Camera cam = oblique(v);
    for (bool eightBit : {false, true}) {
      caster.setPreintegrationEightBit(eightBit);
      // Post-classified adaptive steps (the page's default): the table's
      // opacity read as log2 of the transmittance (LOG_TRANSMITTANCE).
      for (auto [pre, adaptive] : {std::pair{true, false}, {true, true}, {false, true}}) {
        if (!pre && eightBit) continue;  // no pre-integration table to vary
        const RenderSettings s = sampling(pre, adaptive);
        const Twin t = renderTwin(caster, v, visibleTf(), cam, s, 96);
        const double db = psnr(t.gpu, t.cpu);
        std::printf("  [measured] es2 %-12s table %-5s GPU vs its reference: %.2f dB\n", name(s),
                    eightBit ? "RGBA8" : "half", db);
        EXPECT_GE(db, 40.0) << name(s) << (eightBit ? " RGBA8" : " half");
      }
    }
  });
}

// Skipping leaves empty blocks for their exit; a pre-integrated ray still
// ends the segment that enters one and starts again just before the exit,
// so what it leaves out is transparent.
TEST(Sampling, SkippingDoesNotChangePreintegratedImages) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSheppLogan({48, 48, 48});
  auto layout = layout::Texture3DLayout::create(v, gpu::DeviceLimits::of(c.caps()), c.ledger());
  render::Raycaster skipping(c, v, *layout);
  render::Raycaster plain(c, v, *layout);
  plain.setSkipBlockSize(0);
  for (render::Raycaster* r : {&skipping, &plain}) r->setTransferFunction(visibleTf());
  const RenderSettings s = sampling(true, false);
  const Camera cam = oblique(v);
  const Image a = skipping.render(cam, s, 96, 96);
  const Image b = plain.render(cam, s, 96, 96);
  ASSERT_LT(skipping.occupiedBlockFraction(), 1.0) << "the phantom has empty blocks";
  const double db = psnr(a, b);
  std::printf("  [measured] pre-integrated, 8^3 skipping vs none: %.2f dB\n", db);
  EXPECT_GE(db, 60.0);
}

// The test: at step 1 voxel, pre-integration is closer to the fine
// reference than post-classification at step 1, on ch2 with a high-frequency
// TF.
TEST(Sampling, PreintegrationBeatsPostClassificationAtStepOneOnCh2) {
  if (!std::filesystem::exists(kCh2)) GTEST_SKIP() << "mricron-data not installed";
  gpu::GlContext& c = test::gpuContext();
  const Volume v = readVolume(kCh2);
  const TransferFunction tf = spikyTf();
  test::Texture3DCaster t3d(c, v, tf);
  render::Raycaster& caster = t3d.caster;
  Camera cam;
  cam.frame(v);
  const int size = 160;
  const Image fine = fineReference(v, tf, cam, RenderSettings(), size);
  const double post = psnr(caster.render(cam, sampling(false, false, 1.0), size, size), fine);
  const double pre = psnr(caster.render(cam, sampling(true, false, 1.0), size, size), fine);
  const double post05 = psnr(caster.render(cam, sampling(false, false, 0.5), size, size), fine);
  std::printf(
      "  [measured] ch2, spiky TF, vs 0.25-voxel reference: step 1 post-classified %.2f dB, "
      "pre-integrated %.2f dB (step 0.5 post-classified %.2f dB)\n",
      post, pre, post05);
  EXPECT_GT(pre, post + 3.0);
}

// Adaptive steps on ch2 with the default TF: fewer samples, and the image
// still >= 40 dB against the fine reference.
TEST(Sampling, AdaptiveStepsTakeFewerSamplesOnCh2AndKeepTheImage) {
  if (!std::filesystem::exists(kCh2)) GTEST_SKIP() << "mricron-data not installed";
  gpu::GlContext& c = test::gpuContext();
  const Volume v = readVolume(kCh2);
  const TransferFunction tf = TransferFunction::preset("mr-default");
  test::Texture3DCaster t3d(c, v, tf);
  render::Raycaster& caster = t3d.caster;
  const Camera cam = oblique(v);
  const int size = 128;
  const Image fine = fineReference(v, tf, cam, RenderSettings(), size);
  const Twin plain = renderTwin(caster, v, tf, cam, sampling(false, false), size);
  for (bool pre : {false, true}) {
    const Twin adaptive = renderTwin(caster, v, tf, cam, sampling(pre, true), size);
    const double twin = psnr(adaptive.gpu, adaptive.cpu);
    const double quality = psnr(adaptive.gpu, fine);
    std::printf(
        "  [measured] ch2 mr-default step 0.5 %s: %.1f samples/ray (plain %.1f), %.2f dB vs "
        "its reference, %.2f dB vs the fine one (plain %.2f dB)\n",
        pre ? "pre+adaptive" : "adaptive",
        static_cast<double>(adaptive.stats.samples) / adaptive.stats.raysHittingVolume,
        static_cast<double>(plain.stats.samples) / plain.stats.raysHittingVolume, twin, quality,
        psnr(plain.gpu, fine));
    EXPECT_LT(adaptive.stats.samples, plain.stats.samples * 3 / 4);
    EXPECT_GE(twin, 40.0);
    EXPECT_GE(quality, 40.0);
  }
}

// Adaptive steps stay on the base lattice: a clip plane moving by a fraction
// of a step changes no pixel, pre-integrated or not.
TEST(Sampling, MovingAClipPlaneBySubStepKeepsTheSamples) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSheppLogan({40, 40, 40});
  test::Texture3DCaster t3d(c, v, visibleTf());
  render::Raycaster& caster = t3d.caster;
  const Camera cam = test::topDownOrthographic(v.extent());
  for (bool pre : {false, true}) {
    const RenderSettings s = sampling(pre, true);
    const test::SubStepClip r = test::renderSubStepClip(caster, v, cam, s, 80);
    EXPECT_EQ(psnr(r.cut, r.nudged), std::numeric_limits<double>::infinity()) << pre;
    EXPECT_LT(psnr(r.cut, r.uncut), 40.0) << "the plane must cut";
    RenderSettings clipped = r.clipped;
    clipped.clipping.cropMin = {0.1, 0.0, 0.0};
    const Twin t = renderTwin(caster, v, visibleTf(), cam, clipped, 80);
    const double db = psnr(t.gpu, t.cpu);
    std::printf("  [measured] clipped %s vs its reference %.2f dB\n", name(s), db);
    EXPECT_GE(db, 40.0);
  }
}

TEST(Sampling, TheTableIsRebuiltWhenTheTfChangesOnly) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSphere({24, 24, 24});
  test::Texture3DCaster t3d(c, v, visibleTf());
  render::Raycaster& caster = t3d.caster;
  Camera cam;
  cam.frame(v.extent());
  const RenderSettings s = sampling(true, true);
  caster.render(cam, s, 32, 32);
  cam.azimuthDeg = 40;
  caster.render(cam, s, 32, 32);
  EXPECT_EQ(caster.preintegrationTable().builds(), 1);
  caster.setTransferFunction(TransferFunction::preset("ct-bone"));
  caster.render(cam, s, 32, 32);
  EXPECT_EQ(caster.preintegrationTable().builds(), 2);
  std::printf("  [measured] pre-integration table 256^2: %.2f ms to build, %.2f ms to upload\n",
              caster.preintegrationTable().lastBuildMs(),
              caster.preintegrationTable().lastUploadMs());
  EXPECT_EQ(caster.preintegrationTable().entries(), 256);
}
