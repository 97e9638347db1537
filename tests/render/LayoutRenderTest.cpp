// The ray caster on every layout, in ES 2.0 and ES 3.0 contexts: against
// texture3d and against the CPU reference (the layouts' image tests).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "support/EachApi.h"
#include "support/GpuTestContext.h"
#include "support/TestCameras.h"
#include "support/TestSupport.h"
#include "support/TestTransferFunctions.h"
#include "tessera/gpu/DeviceSession.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/layout/MosaicLayout.h"
#include "tessera/layout/PackedMosaicLayout.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/lod/InCoreVolumeSource.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/Raycaster.h"
#include "tessera/render/TechniqueRegistry.h"

using namespace tessera;

namespace {

const char* kCh2 = "/usr/share/mricron/templates/ch2.nii.gz";

using test::visibleTf;

Image renderWith(gpu::GlContext& c, const Volume& v, const layout::Layout& layout,
                 const TransferFunction& tf, const Camera& cam, const RenderSettings& s, int size,
                 int skipBlock = 8) {
  render::Raycaster caster(c, v, layout);
  caster.setSkipBlockSize(skipBlock);
  caster.setTransferFunction(tf);
  return caster.render(cam, s, size, size);
}

// A volume with slice counts that make packed-mosaic seams fall inside it.
Volume seamVolume() {
  return makeSheppLogan({37, 53, 29});
}

}  // namespace

using LayoutRenderOnEachApi = test::EachApi;
INSTANTIATE_TEST_SUITE_P(Api, LayoutRenderOnEachApi, test::kEveryApi, test::apiParamName);

// On ES 3 they also match texture3d.
TEST_P(LayoutRenderOnEachApi, MosaicAndPackedMatchReference) {
  const gpu::ApiLevel api = GetParam();
  gpu::GlContext& c = context();
  const Volume v = seamVolume();
  gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  // Small textures force the packed layout across channels and textures:
  // 37x53 tiles, 2 per 128x128 texture... 29 slices need 4 textures.
  gpu::DeviceLimits packedLimits = limits;
  packedLimits.max2DTextureSize = 128;
  auto mosaic = layout::MosaicLayout::create(v, limits, c.ledger());
  auto packed = layout::PackedMosaicLayout::create(v, packedLimits, c.ledger(), 6);
  std::printf("  [plan] %s\n", packed->plan().reason.c_str());
  EXPECT_GE(packed->textureUnits(), 2) << "the test must cross texture seams";
  Camera cam = test::orbitCamera(v.extent(), 35, 25);
  RenderSettings s;
  const Image ref = renderReference(v, visibleTf(), cam, s, 96, 96);
  const Image viaMosaic = renderWith(c, v, *mosaic, visibleTf(), cam, s, 96);
  const Image viaPacked = renderWith(c, v, *packed, visibleTf(), cam, s, 96);
  EXPECT_GE(psnr(viaMosaic, ref), 40.0);
  EXPECT_GE(psnr(viaPacked, ref), 40.0);
  std::printf("  [measured] %s: mosaic vs reference %.2f dB, packed vs reference %.2f dB\n",
              api == gpu::ApiLevel::Gles2 ? "ES2" : "ES3", psnr(viaMosaic, ref),
              psnr(viaPacked, ref));
  if (api == gpu::ApiLevel::Gles3) {
    auto t3d = layout::Texture3DLayout::create(v, limits, c.ledger());
    const Image via3d = renderWith(c, v, *t3d, visibleTf(), cam, s, 96);
    EXPECT_GE(psnr(viaMosaic, via3d), 45.0);
    EXPECT_GE(psnr(viaPacked, via3d), 45.0);
    std::printf("  [measured] ES3: mosaic vs texture3d %.2f dB, packed vs texture3d %.2f dB\n",
                psnr(viaMosaic, via3d), psnr(viaPacked, via3d));
  }
}

TEST(LayoutRender, Es2MatchesEs3ImageOfTheSameLayout) {
  const Volume v = seamVolume();
  Camera cam = test::orbitCamera(v.extent(), -50, 10);
  RenderSettings s;
  s.jitter = true;
  gpu::GlContext& c3 = test::gpuContext();
  auto m3 = layout::MosaicLayout::create(v, gpu::DeviceLimits::of(c3.caps()), c3.ledger());
  const Image es3 = renderWith(c3, v, *m3, visibleTf(), cam, s, 80);
  gpu::GlContext::Options o;
  o.api = gpu::ApiLevel::Gles2;
  auto c2 = gpu::GlContext::createHeadless(o);
  auto m2 = layout::MosaicLayout::create(v, gpu::DeviceLimits::of(c2->caps()), c2->ledger());
  const Image es2 = renderWith(*c2, v, *m2, visibleTf(), cam, s, 80);
  EXPECT_GE(psnr(es2, es3), 45.0);
  m2.reset();
  c2.reset();
  test::gpuContext();
}

namespace {

// Noguera & Jiménez 2012's capacity figures, really allocated: the volume
// planned on `profile` without downsampling as packed-mosaic in `textures`
// RGBA textures of `side`^2, uploaded (the ledger proving the bytes, within
// the profile's budget) and rendered like the reference.
void expectPaperCapacity(const char* profile, Volume volume, int textures, int side) {
  const test::BudgetOverride keep(HostBudget::global().limitBytes());
  gpu::DeviceSession device = gpu::openDevice(profile);
  {
    render::TechniqueOnVolume t = render::createTechnique(
        "raycast", *device.context, device.limits, lod::InCoreVolumeSource(std::move(volume)),
        {.imageSize = {96, 96}});
    const Volume& v = *t.upload.volume;
    ASSERT_EQ(t.upload.plan.layout.layout, "packed-mosaic");
    ASSERT_FALSE(t.upload.plan.downsampled());
    const layout::Layout& layout = *t.upload.layout;
    EXPECT_EQ(layout.textureUnits(), textures);
    EXPECT_EQ(layout.textureBytes(), static_cast<std::uint64_t>(textures) * side * side * 4);
    Camera cam = test::orbitCamera(v.extent(), 20, 0);
    RenderSettings s;
    s.stepVoxels = 2.0;  // keep the test quick; the comparison is what matters
    t.technique->setTransferFunction(visibleTf());
    const Image img = t.technique->renderImage(cam, s, 96, 96);
    const Image ref = renderReference(v, visibleTf(), cam, s, 96, 96);
    EXPECT_GE(psnr(img, ref), 40.0);
    EXPECT_GE(device.context->ledger().peakBytes(), layout.textureBytes());
    EXPECT_LE(device.context->ledger().peakBytes(), device.limits.textureBudget);
  }
  device.context.reset();
  test::gpuContext();
}

}  // namespace

TEST(LayoutRender, PaperCapacityIpad2RendersA512x512x384Volume) {
  // The largest iPad 2 model: six RGBA 2048^2 textures in an ES 2.0 context.
  expectPaperCapacity("ipad2", makeSheppLogan({512, 512, 384}), 6, 2048);
}

TEST(LayoutRender, PaperCapacityWebgl1RendersA512x512x1024VolumeFromOne8192Texture) {
  // The WebGL desktop browser of 2012: all 1024 slices in one RGBA 8192^2.
  // A sphere (its radial ramp crosses every slice, channel and tile seam) is
  // generated 5x faster than the phantom at 256 M voxels.
  expectPaperCapacity("webgl1-desktop-2012", makeSphere({512, 512, 1024}), 1, 8192);
}

TEST(LayoutRender, EveryBuiltinProfileRendersCh2WithinItsBudget) {
  if (!std::filesystem::exists(kCh2)) GTEST_SKIP() << "mricron-data not installed";
  for (const gpu::DeviceProfile& profile : gpu::DeviceProfile::builtins()) {
    const test::BudgetOverride keep(HostBudget::global().limitBytes());
    gpu::DeviceSession device = gpu::openDevice(profile.name);
    render::TechniqueOnVolume t =
        render::createTechnique("raycast", *device.context, device.limits,
                                lod::InCoreVolumeSource(readVolume(kCh2)), {.imageSize = {96, 96}});
    const layout::Plan& plan = t.upload.plan;
    const Volume& v = *t.upload.volume;
    if (plan.downsampled()) {
      EXPECT_NE(plan.reason.find("downsampled"), std::string::npos) << plan.reason;
    }
    Camera cam = test::orbitCamera(v.extent(), 30, 0);
    RenderSettings s;
    t.technique->setTransferFunction(TransferFunction::preset("mr-default"));
    const Image img = t.technique->renderImage(cam, s, 96, 96);
    const Image ref = renderReference(v, TransferFunction::preset("mr-default"), cam, s, 96, 96);
    const double db = psnr(img, ref);
    EXPECT_GE(db, 40.0) << profile.name;
    if (device.limits.textureBudget) {
      EXPECT_LE(device.context->ledger().peakBytes(), device.limits.textureBudget) << profile.name;
    }
    std::printf("  [measured] %-20s %-13s %s, %.2f dB, GPU peak %llu bytes\n", profile.name.c_str(),
                plan.layout.layout.c_str(), plan.downsampled() ? "downsampled" : "full res", db,
                static_cast<unsigned long long>(device.context->ledger().peakBytes()));
    t = {};  // the technique and the volume's textures, while their context lives
    device.context.reset();
  }
  test::gpuContext();
}
