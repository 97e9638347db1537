#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "support/GpuTestContext.h"
#include "support/LabelPalette.h"
#include "support/TestSupport.h"
#include "support/TestTransferFunctions.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/gpu/DeviceSession.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/Planner.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/render/LabelTable.h"
#include "tessera/render/Raycaster.h"
#include "tessera/render/Slice2DRenderer.h"
#include "tessera/render/Slice3DRenderer.h"
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/viewer/Viewer.h"

namespace tessera::viewer {
namespace {

constexpr int kSize = 96;

Image readFramebuffer(const gpu::Framebuffer& fb) {
  Image img(fb.width(), fb.height());
  fb.readRgba8(img.rgba().data());
  img.flipVertically();
  return img;
}

// What `tessera render` shows for the same view: the plain ray caster.
Image directRender(gpu::GlContext& ctx, const Volume& v, const TransferFunction& tf,
                   const Camera& cam, const RenderSettings& s) {
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(ctx.caps());
  const layout::Plan plan = layout::planLayout(v, limits, {});
  auto layout = layout::createLayout(plan, v, limits, ctx.ledger());
  render::Raycaster caster(ctx, v, *layout);
  caster.setTransferFunction(tf);
  return caster.render(cam, s, kSize, kSize);
}

struct ViewerFixture : ::testing::Test {
  gpu::GlContext& ctx = test::gpuContext();
  gpu::Framebuffer fb = gpu::Framebuffer::create(ctx.ledger(), "test view", kSize, kSize);
};

// The clip plane that follows the camera faces the viewer from every angle:
// the frame equals the ray caster with that plane, and turning the camera
// turns the plane (an explicit plane along the first view would not turn).
TEST_F(ViewerFixture, ClipPlaneFollowsTheCamera) {
  Viewer v(ctx, gpu::DeviceProfile::find("gles3"));
  v.setVolume(makeSheppLogan({40, 40, 40}), "phantom");
  v.showBoundingBox = v.showAxes = false;
  v.quality = Quality::Full;
  v.clipPlaneFollowsCamera = true;
  v.followingPlaneDistance = 0.0;
  for (double azimuth : {0.0, 70.0}) {
    v.camera().azimuthDeg = azimuth;
    const RenderSettings s = v.frameSettings();
    ASSERT_EQ(s.clipping.planes.size(), 1u);
    const glm::dvec3 back = v.camera().worldBasis()[2];
    EXPECT_NEAR(glm::dot(s.clipping.planes[0].normal, back), 1.0, 1e-12);
    v.render(kSize, kSize, fb.id());
    const Image shown = readFramebuffer(fb);
    EXPECT_GE(
        psnr(shown, directRender(ctx, v.volume(), v.tfEditor().transferFunction(), v.camera(), s)),
        60.0);
    EXPECT_LT(psnr(shown, directRender(ctx, v.volume(), v.tfEditor().transferFunction(), v.camera(),
                                       v.settings())),
              40.0)
        << "the plane must cut";
  }
}

TEST_F(ViewerFixture, FrameShowsWhatTheRayCasterRenders) {
  Viewer v(ctx, gpu::DeviceProfile::find("gles3"));
  v.setVolume(makeSheppLogan({48, 48, 48}), "phantom");
  v.showBoundingBox = v.showAxes = false;
  v.camera().azimuthDeg = 30.0;
  const FrameStats fs = v.render(kSize, kSize, fb.id());
  EXPECT_GT(fs.ms, 0.0);
  EXPECT_EQ(fs.renderWidth, kSize);
  const Image shown = readFramebuffer(fb);
  const Image direct =
      directRender(ctx, v.volume(), v.tfEditor().transferFunction(), v.camera(), v.settings());
  EXPECT_GE(psnr(shown, direct), 60.0);
}

// A label volume in the viewer renders as `tessera render --labels` does
// (the same preparation, settings and 256-entry categorical table: the ray
// caster with render::applyLabelSettings and render::kLabelLutSize), and
// with opaque labels no colour outside the table appears. Hiding a label
// removes its colour; clearLabels goes back to an interpolated volume.
TEST_F(ViewerFixture, LabelVolumesRenderAsTheRenderCommandsLabels) {
  Volume labels = Volume::allocate({20, 18, 16}, ScalarType::U8, "labels");
  std::mt19937 rng(7);
  for (std::size_t i = 0; i < static_cast<std::size_t>(labels.voxelCount()); ++i) {
    labels.setValueAtIndex(i, static_cast<double>(rng() % 31));  // 0: background
  }
  labels.invalidateRange();
  Viewer v(ctx, gpu::DeviceProfile::find("gles3"));
  v.setVolume(labels, "labels");
  v.showBoundingBox = v.showAxes = false;
  v.quality = Quality::Full;
  v.camera().azimuthDeg = 33;
  v.camera().elevationDeg = 21;
  v.setLabelsDefault();
  ASSERT_TRUE(v.labelsOn());
  EXPECT_TRUE(v.settings().nearest);
  ASSERT_EQ(v.labelTable().labels.size(), 30u);

  // `tessera render --labels` without a table: the same steps on the file's volume.
  Volume prepared = labels;
  render::prepareLabelVolume(prepared);
  const render::LabelTable table = render::LabelTable::defaultFor(prepared);
  const TransferFunction tf = table.toTransferFunction();
  RenderSettings s = v.frameSettings();
  render::applyLabelSettings(s);
  auto renderCommand = [&](const TransferFunction& t) {
    const gpu::DeviceLimits limits = gpu::DeviceLimits::of(ctx.caps());
    const layout::Plan plan = layout::planLayout(prepared, limits, {});
    auto layout = layout::createLayout(plan, prepared, limits, ctx.ledger());
    render::Raycaster caster(ctx, prepared, *layout);
    caster.setLutSize(render::kLabelLutSize);
    caster.setTransferFunction(t);
    return caster.render(v.camera(), s, kSize, kSize);
  };
  v.render(kSize, kSize, fb.id());
  const Image shown = readFramebuffer(fb);
  const double p = psnr(shown, renderCommand(tf));
  std::printf("  [measured] viewer labels vs render --labels: %.1f dB\n", p);
  EXPECT_GE(p, 50.0);

  auto outsideTable = [&](const Image& img, int& drawn) {
    const test::PaletteCount n = test::countAgainstPalette(img, table);
    drawn = n.drawn;
    return n.outside;
  };
  int drawn = 0;
  EXPECT_EQ(outsideTable(shown, drawn), 0);
  EXPECT_GT(drawn, 1000);

  // Hiding label 5 in the viewer equals the table with label 5 hidden.
  v.setLabelVisible(5, false);
  render::LabelTable hidden = table;
  hidden.labels.at(5).visible = false;
  v.render(kSize, kSize, fb.id());
  const Image withoutFive = readFramebuffer(fb);
  EXPECT_GE(psnr(withoutFive, renderCommand(hidden.toTransferFunction())), 50.0);
  EXPECT_LT(psnr(withoutFive, shown), 50.0) << "hiding a label must change the frame";
  v.setAllLabelsVisible(false);
  v.render(kSize, kSize, fb.id());
  EXPECT_EQ(outsideTable(readFramebuffer(fb), drawn), 0);
  EXPECT_EQ(drawn, 0) << "all labels hidden: only the background";

  v.clearLabels();
  EXPECT_FALSE(v.labelsOn());
  EXPECT_FALSE(v.settings().nearest);
  v.render(kSize, kSize, fb.id());
  EXPECT_GE(psnr(readFramebuffer(fb), directRender(ctx, v.volume(), v.tfEditor().transferFunction(),
                                                   v.camera(), v.frameSettings())),
            60.0);
}

// A volume that is not a label volume is refused with a clear error, and
// the viewer keeps rendering it as before.
TEST_F(ViewerFixture, NonLabelVolumesAreRefusedAsLabels) {
  Viewer v(ctx, gpu::DeviceProfile::find("gles3"));
  Volume ramp = Volume::allocate({8, 8, 8}, ScalarType::F32, "ramp");
  for (std::size_t i = 0; i < static_cast<std::size_t>(ramp.voxelCount()); ++i) {
    ramp.setValueAtIndex(i, 0.5 * static_cast<double>(i % 7));
  }
  ramp.invalidateRange();
  v.setVolume(ramp, "ramp");
  try {
    v.setLabelsDefault();
    ADD_FAILURE() << "a ramp of halves is not a label volume";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("labels must be integers"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(v.labelsOn());
  EXPECT_FALSE(v.settings().nearest);
}

// The ray cast and the composite are scissored to the part of the view the
// volume box covers (the ray cast also to the last frame's part, which its
// target still holds): as the box moves across the view, shrinks and grows,
// every frame equals a whole frame of the ray caster.
TEST_F(ViewerFixture, FramesScissoredToTheVolumeEqualWholeFrames) {
  Viewer v(ctx, gpu::DeviceProfile::find("gles3"));
  v.setVolume(makeSheppLogan({48, 48, 48}), "phantom");
  v.showBoundingBox = v.showAxes = false;
  v.quality = Quality::Full;
  for (Projection projection : {Projection::Orthographic, Projection::Perspective}) {
    v.camera().projection = projection;
    for (const glm::dvec3 view : {glm::dvec3(0.5, -0.25, 0.1), glm::dvec3(0.5, 0.3, -0.2),
                                  glm::dvec3(0.3, 0.0, 0.0), glm::dvec3(1.0, 0.0, 0.0)}) {
      v.camera().zoom = view.x;
      v.camera().target = glm::dvec3(0.0);
      v.camera().pan(view.y, view.z);
      v.camera().azimuthDeg += 25.0;
      v.render(kSize, kSize, fb.id());
      EXPECT_GE(
          psnr(readFramebuffer(fb), directRender(ctx, v.volume(), v.tfEditor().transferFunction(),
                                                 v.camera(), v.settings())),
          60.0)
          << "zoom " << view.x << ", pan " << view.y << " " << view.z;
    }
  }
}

TEST_F(ViewerFixture, SlicingTechniquesShowWhatTheSlicersRender) {
  Viewer v(ctx, gpu::DeviceProfile::find("gles3"));
  v.setVolume(makeSheppLogan({40, 40, 40}), "phantom");
  v.showBoundingBox = v.showAxes = false;
  v.camera().azimuthDeg = 20.0;
  const std::vector<std::string> names = render::TechniqueRegistry::global().names();
  for (const char* name : {"slice3d", "slice2d"}) {
    SCOPED_TRACE(name);
    ASSERT_NE(std::find(names.begin(), names.end(), name), names.end());
    v.setTechnique(name);
    EXPECT_EQ(v.technique(), name);
    v.render(kSize, kSize, fb.id());
    const Image shown = readFramebuffer(fb);
    const TransferFunction& tf = v.tfEditor().transferFunction();
    Image direct;
    // The viewer's device (its profile's limits: RGBA8 accumulation where
    // the profile has no float render targets).
    const gpu::DeviceLimits& limits = v.limits();
    const layout::Plan plan = layout::planLayout(v.volume(), limits, {});
    auto layout = layout::createLayout(plan, v.volume(), limits, ctx.ledger());
    if (std::string(name) == "slice3d") {
      render::Slice3DRenderer slicer(ctx, v.volume(), *layout, limits.halfFloatRenderTargets);
      slicer.setTransferFunction(tf);
      direct = slicer.render(v.camera(), v.settings(), kSize, kSize);
    } else {
      render::Slice2DRenderer slicer(ctx, v.volume(),
                                     {.halfFloatAccumulation = limits.halfFloatRenderTargets});
      slicer.setTransferFunction(tf);
      direct = slicer.render(v.camera(), v.settings(), kSize, kSize);
    }
    EXPECT_GE(psnr(shown, direct), 50.0);
    // And it is a picture of the volume: close to the ray caster's.
    const Image cast = directRender(ctx, v.volume(), tf, v.camera(), v.settings());
    EXPECT_GE(psnr(shown, cast), 25.0);
  }
}

TEST_F(ViewerFixture, OverlaysTfEditsAndWindowChangeTheFrame) {
  Viewer v(ctx, gpu::DeviceProfile::find("gles3"));
  v.setVolume(makeSheppLogan({40, 40, 40}), "phantom");
  v.showBoundingBox = v.showAxes = false;
  v.render(kSize, kSize, fb.id());
  const Image plain = readFramebuffer(fb);
  v.showBoundingBox = v.showAxes = true;
  v.render(kSize, kSize, fb.id());
  const Image boxed = readFramebuffer(fb);
  EXPECT_LT(psnr(plain, boxed), 40.0);
  v.showBoundingBox = v.showAxes = false;
  v.tfEditor().addOpacityPoint(0.5, 1.0);
  v.render(kSize, kSize, fb.id());
  const Image edited = readFramebuffer(fb);
  EXPECT_LT(psnr(plain, edited), 40.0);
  v.setWindowLevel(50.0, 100.0);
  v.render(kSize, kSize, fb.id());
  EXPECT_LT(psnr(edited, readFramebuffer(fb)), 40.0);
}

// Pixels where two frames differ by more than `tolerance` in R, G or B.
int differingPixels(const Image& a, const Image& b, int tolerance) {
  int n = 0;
  for (std::size_t i = 0; i < a.rgba().size(); i += 4) {
    for (std::size_t c = 0; c < 3; ++c) {
      if (std::abs(a.rgba()[i + c] - b.rgba()[i + c]) > tolerance) {
        ++n;
        break;
      }
    }
  }
  return n;
}

// An opaque box seen from a corner of the (+x, +y, +z) octant: the axes run
// along the three edges at the far, minimum corner (between back faces) and
// must vanish behind the volume; the box's edges at the near corner lie on
// front faces and must show.
TEST_F(ViewerFixture, LinesBehindAnOpaqueVolumeAreHiddenAndLinesInFrontDrawn) {
  Viewer v(ctx, gpu::DeviceProfile::find("gles3"));
  v.setVolume(makeSheppLogan({40, 40, 40}), "phantom");
  const TransferFunction opaque = test::tfFromPoints(
      {{0.0, {0.2, 0.3, 0.9}}, {1.0, {0.9, 0.9, 0.2}}}, {{0.0, 1.0}, {1.0, 1.0}});
  v.tfEditor().setTransferFunction(opaque);
  v.quality = Quality::Full;
  bool cornerView = false;
  for (double azimuth : {45.0, -45.0, 135.0, -135.0}) {
    v.camera().azimuthDeg = azimuth;
    v.camera().elevationDeg = 30.0;
    const glm::dvec3 eye = v.camera().eye();
    if (eye.x > 0.0 && eye.y > 0.0 && eye.z > 0.0) {
      cornerView = true;
      break;
    }
  }
  ASSERT_TRUE(cornerView);
  auto frame = [&](bool box, bool axes) {
    v.showBoundingBox = box;
    v.showAxes = axes;
    v.render(kSize, kSize, fb.id());
    return readFramebuffer(fb);
  };
  const Image plain = frame(false, false);
  const Image axes = frame(false, true);
  const Image box = frame(true, false);
  // Lit: the volume covers a good part of the view, opaque.
  int lit = 0;
  for (std::size_t i = 0; i < plain.rgba().size(); i += 4) lit += plain.rgba()[i + 2] > 40;
  EXPECT_GT(lit, kSize * kSize / 5);
  EXPECT_EQ(differingPixels(plain, axes, 2), 0);
  // The three near edges (and the silhouette's six) are drawn.
  EXPECT_GT(differingPixels(plain, box, 8), 3 * kSize / 2);
  // The axes are in view: with a transparent volume they show.
  TransferFunction clear = opaque;
  clear.opacities.clear();
  clear.addOpacity(0.0, 0.0);
  clear.addOpacity(1.0, 0.0);
  v.tfEditor().setTransferFunction(clear);
  EXPECT_GT(differingPixels(frame(false, false), frame(false, true), 8), kSize / 4);
}

TEST_F(ViewerFixture, VolumePixelCapRendersSmallerAndUpscales) {
  Viewer v(ctx, gpu::DeviceProfile::find("gles3"));
  v.setVolume(makeSheppLogan({40, 40, 40}), "phantom");
  v.quality = Quality::Full;
  v.showBoundingBox = v.showAxes = false;
  const Image full = (v.render(kSize, kSize, fb.id()), readFramebuffer(fb));
  v.maxVolumePixels = kSize * kSize / 4;
  const FrameStats fs = v.render(kSize, kSize, fb.id());
  EXPECT_EQ(fs.renderWidth, kSize / 2);
  EXPECT_EQ(fs.renderHeight, kSize / 2);
  const double p = psnr(readFramebuffer(fb), full);
  EXPECT_GT(p, 25.0);
  EXPECT_LT(p, 60.0);
}

// A slow full-quality frame is rendered in strips across refine() calls
// (a preview first), and the finished frame is the one render() draws at once.
TEST_F(ViewerFixture, ProgressiveFramesRefineInStripsToTheFullFrame) {
  Viewer v(ctx, gpu::DeviceProfile::find("gles3"));
  v.setVolume(makeSheppLogan({40, 40, 40}), "phantom");
  v.camera().azimuthDeg = 30.0;
  for (const char* technique : {"raycast", "slice3d", "slice2d"}) {
    SCOPED_TRACE(technique);
    v.setTechnique(technique);
    v.progressive = false;
    v.render(kSize, kSize, fb.id());
    const Image whole = readFramebuffer(fb);
    v.progressive = true;
    v.frameBudgetMs = 1e-3;  // every frame is "slow": one strip per call
    const FrameStats preview = v.render(kSize, kSize, fb.id());
    EXPECT_FALSE(preview.complete);
    EXPECT_TRUE(v.refining());
    EXPECT_LE(preview.renderWidth, kSize);  // the interaction level: full size when cheap
    int calls = 0;
    while (v.refining() && calls < 10 * kSize) {
      const FrameStats part = v.refine();
      EXPECT_EQ(part.complete, !v.refining());
      ++calls;
    }
    EXPECT_FALSE(v.refining());
    EXPECT_GE(calls, 8);
    EXPECT_TRUE(v.lastFrame().complete);
    EXPECT_GE(psnr(readFramebuffer(fb), whole), 60.0);
    // A new frame cancels the refinement in progress.
    v.render(kSize, kSize, fb.id());
    v.refine();
    v.camera().azimuthDeg += 10.0;
    v.progressive = false;
    v.render(kSize, kSize, fb.id());
    EXPECT_FALSE(v.refining());
    v.camera().azimuthDeg -= 10.0;
  }
}

TEST_F(ViewerFixture, FailedLoadKeepsThePreviousVolume) {
  Viewer v(ctx, gpu::DeviceProfile::find("gles3"));
  v.setVolume(makeSheppLogan({32, 32, 32}), "phantom");
  EXPECT_THROW(v.setVolume(Volume{}, "empty"), InputError);
  EXPECT_EQ(v.volumeName(), "phantom");
  EXPECT_EQ(v.volume().dims(), glm::ivec3(32));
  EXPECT_THROW(v.setTechnique("no-such-technique"), InputError);
  EXPECT_EQ(v.technique(), "raycast");
  v.render(kSize, kSize, fb.id());
  EXPECT_GT(v.lastFrame().ms, 0.0);
}

// `tessera view --profile` obeys the profile as `tessera render --profile`
// does: the same effective limits, GPU budget and host budget, so a volume
// the render command would refuse to hold is refused by the viewer too.
TEST_F(ViewerFixture, AppliesTheProfilesHostBudgetLikeTheRenderCommand) {
  const test::TempDir dir;
  const std::string file = (dir / "small-host.json").string();
  std::ofstream(file)
      << R"({"name": "small-host", "api": "gles3", "texture_budget_mb": 64, "host_budget_mb": 48})";
  const test::BudgetOverride keep(HostBudget::global().limitBytes());
  ASSERT_GT(HostBudget::global().limitBytes(), 48ull << 20);  // else the test proves nothing

  gpu::DeviceLimits renderLimits;
  std::uint64_t renderHostBudget = 0;
  {
    const test::BudgetOverride inner(HostBudget::global().limitBytes());
    const gpu::DeviceSession device = gpu::openDevice(file);  // what `tessera render` opens
    renderLimits = device.limits;
    renderHostBudget = HostBudget::global().limitBytes();
  }
  ctx.makeCurrent();
  ASSERT_EQ(renderHostBudget, 48ull << 20);

  struct KeepLedgerBudget {
    gpu::MemoryLedger& ledger;
    std::uint64_t saved;
    ~KeepLedgerBudget() { ledger.setBudget(saved); }
  } keepLedger{ctx.ledger(), ctx.ledger().budget()};
  Viewer v(ctx, gpu::DeviceProfile::find(file));
  EXPECT_EQ(HostBudget::global().limitBytes(), renderHostBudget);
  EXPECT_EQ(v.limits().hostBudget, renderLimits.hostBudget);
  EXPECT_EQ(v.limits().textureBudget, renderLimits.textureBudget);
  EXPECT_EQ(ctx.ledger().budget(), 64ull << 20);
  EXPECT_THROW(Volume::allocate({512, 512, 256}, ScalarType::U8, "too big"), BudgetError);
  v.setVolume(makeSheppLogan({32, 32, 32}), "phantom");  // what fits still loads
  EXPECT_EQ(v.volume().dims(), glm::ivec3(32));
}

// The adaptive quality is the issue-5 controller: measured frame times drive
// the resolution towards the goal, down to its floor for an impossible goal
// and up to full size for a generous one.
TEST_F(ViewerFixture, AdaptiveQualityFollowsTheFrameTimeGoal) {
  Viewer v(ctx, gpu::DeviceProfile::find("gles3"));
  v.setVolume(makeSheppLogan({32, 32, 32}), "phantom");
  v.qualityController() = render::QualityController({.goalMs = 1e-6});
  v.controller().pointerDown(0, {10, 10});
  int width = 0;
  for (int i = 0; i < 30; ++i) width = v.render(kSize, kSize, fb.id()).renderWidth;
  EXPECT_EQ(width, kSize / 8);                             // minResolutionScale
  EXPECT_EQ(v.qualityController().next().stepScale, 4.0);  // then the step grew to its cap
  v.controller().pointerUp(0);
  EXPECT_EQ(v.render(kSize, kSize, fb.id()).renderWidth, kSize);  // idle: full quality

  v.qualityController() = render::QualityController({.goalMs = 1e6});
  v.controller().pointerDown(0, {10, 10});
  for (int i = 0; i < 30; ++i) width = v.render(kSize, kSize, fb.id()).renderWidth;
  EXPECT_EQ(width, kSize);
}

TEST_F(ViewerFixture, AdaptiveQualityRendersHalfSizeWhileInteracting) {
  Viewer v(ctx, gpu::DeviceProfile::find("gles3"));
  v.setVolume(makeSheppLogan({32, 32, 32}), "phantom");
  v.quality = Quality::Adaptive;
  v.controller().pointerDown(0, {10, 10});
  EXPECT_EQ(v.render(kSize, kSize, fb.id()).renderWidth, kSize / 2);
  v.controller().pointerUp(0);
  EXPECT_EQ(v.render(kSize, kSize, fb.id()).renderWidth, kSize);
  v.quality = Quality::Full;
  v.controller().pointerDown(0, {10, 10});
  EXPECT_EQ(v.render(kSize, kSize, fb.id()).renderWidth, kSize);
}

TEST(Viewer, Es2ContextUsesATwoDimensionalLayout) {
  gpu::GlContext::Options o;
  o.api = gpu::ApiLevel::Gles2;
  auto ctx = gpu::GlContext::createHeadless(o);
  {
    Viewer v(*ctx, gpu::DeviceProfile::find("webgl1"));
    v.setVolume(makeSheppLogan({40, 40, 40}), "phantom");
    EXPECT_NE(v.plan().layout.layout, "texture3d");
    gpu::Framebuffer fb = gpu::Framebuffer::create(ctx->ledger(), "view", kSize, kSize,
                                                   gpu::TexelFormat::Rgba8Unsized);
    v.showBoundingBox = v.showAxes = false;
    v.render(kSize, kSize, fb.id());
    const Image img = readFramebuffer(fb);
    int lit = 0;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) lit += img.pixel(x, y)[0] > 8 ? 1 : 0;
    EXPECT_GT(lit, kSize * kSize / 20);
  }
  test::gpuContext();  // the shared context current again for later tests
}

}  // namespace
}  // namespace tessera::viewer
