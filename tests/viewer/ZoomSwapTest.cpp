// The zoom-driven level swap (viewer/ZoomSwap.h) end to
// end on ES 3 and ES 2: zooming through the documented thresholds shows
// coarse -> medium -> native block -> medium -> coarse; during each swap
// consecutive frames stay close (the cross-fade spreads the change), where
// the instant swap jumps; after the fade the frame equals a direct render
// of the new stage.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "support/GpuTestContext.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/TexelFormat.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/viewer/Explorer.h"
#include "tessera/viewer/Viewer.h"
#include "tessera/viewer/ZoomSwap.h"

namespace tessera::viewer {
namespace {

constexpr int kSize = 128;
constexpr double kDtMs = 25.0;     // 40 frames/s
constexpr double kFadeMs = 250.0;  // the policy's default: 10 frames
// No pop: during a fade every frame differs from the one before by at most
// a quarter of the instant swap's jump (PSNR at least 12 dB higher; the
// 10-frame fade gives 20) and never by more than 25 dB's worth, where the
// instant swap to the native block falls to 6-10 dB.
constexpr double kFadeGainDb = 12.0;
constexpr double kFadeFloorDb = 25.0;

// Fine detail that a coarser level visibly loses: a sphere of interleaved
// shells and a slanted grating.
std::shared_ptr<Volume> detailedVolume(int n) {
  auto v = std::make_shared<Volume>(Volume::allocate({n, n, n}, ScalarType::U8));
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const glm::dvec3 p = (glm::dvec3(x, y, z) + 0.5) / double(n) - 0.5;
        const double r = glm::length(p);
        double value = 0.0;
        if (r < 0.45) {
          value = 140.0 + 100.0 * std::sin(r * 90.0) * std::cos((p.x + 0.7 * p.y) * 60.0);
        }
        v->setValueAtIndex((std::size_t(z) * n + y) * n + x, std::clamp(value, 0.0, 255.0));
      }
  v->setSpacing({1.0, 1.0, 1.0});
  v->setGeometrySource("test");
  v->setWindow({0.0, 255.0});
  return v;
}

Image read(const gpu::Framebuffer& fb) {
  Image img(fb.width(), fb.height());
  fb.readRgba8(img.rgba().data());
  img.flipVertically();
  return img;
}

int litPixels(const Image& img) {
  int lit = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) lit += img.pixel(x, y)[0] + img.pixel(x, y)[1] > 16;
  return lit;
}

struct Swap {
  int from = 0, to = 0;
  std::vector<Image> frames;  // from the swap's first frame to the end of the fade
};

struct Run {
  std::vector<int> stageSequence;  // the stage shown, each change once
  std::vector<Swap> swaps;
  int maxOverlapFrames = 0;
};

// The zooms: each held for the fade and two frames more. Thresholds for a
// 128^3 volume in a 128 px view with 64^3 grid blocks: medium (level 1)
// from zoom 0.43, native from 2.0; back below 0.8x each.
const double kZooms[] = {0.3, 0.5, 2.2, 1.2, 0.3};

void renderSequence(gpu::GlContext& ctx, const std::string& profile, double fadeMs, Run& run,
                    std::vector<double>& finalDb) {
  auto volume = detailedVolume(128);
  auto source = std::make_shared<lod::InCoreMultiresSource>(volume);
  Explorer explorer(source, 64ull * 64 * 64);
  ASSERT_EQ(explorer.grid().cellSize(), glm::ivec3(32));
  Viewer viewer(ctx, gpu::DeviceProfile::find(profile));
  viewer.quality = Quality::Full;
  viewer.showBoundingBox = viewer.showAxes = false;
  viewer.setVolume(explorer.readLevel(1), "start");
  const lod::ZoomPolicyOptions options{.fadeMs = fadeMs};
  ZoomSwap swap(ctx, explorer, zoomStagesFor(explorer, 1, kSize, options), options);
  const auto& stages = swap.policy().stages();
  ASSERT_EQ(stages.size(), 3u);
  EXPECT_NEAR(stages[1].enterZoom, 1.0 / (4.0 * kSize / std::sqrt(3.0 * 128 * 128)), 1e-9);
  EXPECT_NEAR(stages[2].enterZoom, 2.0, 1e-9);

  gpu::Framebuffer fb = gpu::Framebuffer::create(ctx.ledger(), "zoom view", kSize, kSize,
                                                 gpu::rgba8For(ctx.caps().api));
  const int holdFrames = static_cast<int>(std::ceil(kFadeMs / kDtMs)) + 2;
  Swap* open = nullptr;
  for (const double zoom : kZooms) {
    // The zoom in the shown volume's terms (the native block is framed by
    // its own radius): what the user's wheel sets.
    const double scale = swap.overviewZoom(viewer.camera()) / viewer.camera().zoom;
    viewer.camera().zoom = zoom / scale;
    for (int i = 0; i < holdFrames; ++i) {
      const int before = swap.shownStage();
      const lod::ZoomFrame f = swap.frame(viewer, kDtMs, kSize, kSize, fb.id());
      if (run.stageSequence.empty() || run.stageSequence.back() != f.stage) {
        run.stageSequence.push_back(f.stage);
      }
      if (before >= 0 && f.stage != before) {
        run.swaps.push_back({before, f.stage, {}});
        open = &run.swaps.back();
      }
      if (open) {
        open->frames.push_back(read(fb));
        if (f.from == f.stage) {
          // The fade is over: the frame equals a direct render of the stage.
          Viewer direct(ctx, gpu::DeviceProfile::find(profile));
          direct.quality = Quality::Full;
          direct.showBoundingBox = direct.showAxes = false;
          const lod::ZoomStage& st = stages[static_cast<std::size_t>(f.stage)];
          direct.setVolume(
              st.subVolume ? explorer.readRegion(*swap.shownBox()) : explorer.readLevel(st.level),
              "direct");
          direct.camera() = viewer.camera();
          gpu::Framebuffer dfb = gpu::Framebuffer::create(ctx.ledger(), "direct", kSize, kSize,
                                                          gpu::rgba8For(ctx.caps().api));
          direct.render(kSize, kSize, dfb.id());
          const Image want = read(dfb);
          EXPECT_GT(litPixels(want), kSize * kSize / 64) << st.name;
          finalDb.push_back(psnr(open->frames.back(), want));
          open = nullptr;
        }
      }
    }
  }
  // The native stage's reads were bounded: one 64^3 block, never level 0 whole.
  EXPECT_LE(swap.voxelsRead(), 32ull * 32 * 32 + 64ull * 64 * 64 + 2 * 64ull * 64 * 64);
}

void checkFadeAndInstant(gpu::GlContext& ctx, const std::string& profile) {
  Run fade;
  std::vector<double> finalDb;
  renderSequence(ctx, profile, kFadeMs, fade, finalDb);
  EXPECT_EQ(fade.stageSequence, (std::vector<int>{0, 1, 2, 1, 0}));
  ASSERT_EQ(fade.swaps.size(), 4u);
  for (const double db : finalDb) EXPECT_GE(db, 45.0) << profile;

  Run instant;
  std::vector<double> instantDb;
  renderSequence(ctx, profile, 0.0, instant, instantDb);
  EXPECT_EQ(instant.stageSequence, fade.stageSequence);
  ASSERT_EQ(instant.swaps.size(), fade.swaps.size());
  for (std::size_t s = 0; s < fade.swaps.size(); ++s) {
    const Swap& w = fade.swaps[s];
    ASSERT_GE(w.frames.size(), 5u);
    // The fade: the swap's first frame is the old stage at the new zoom
    // (what an instant swap jumps from); every later frame moves a tenth.
    double minStep = 1e9;
    for (std::size_t i = 1; i < w.frames.size(); ++i) {
      minStep = std::min(minStep, psnr(w.frames[i - 1], w.frames[i]));
    }
    // The instant swap: from the old stage to the new in one frame.
    const Image& instantFrame = instant.swaps[s].frames.front();
    const double jump = psnr(w.frames.front(), instantFrame);
    std::printf(
        "%s swap %d -> %d: fade min per-frame %.1f dB over %zu frames, instant %.1f dB, "
        "after the fade vs direct %.1f dB\n",
        profile.c_str(), w.from, w.to, minStep, w.frames.size(), jump,
        psnr(w.frames.back(), instantFrame));
    EXPECT_GT(minStep, jump + kFadeGainDb) << profile << " swap " << s;
    EXPECT_GT(minStep, kFadeFloorDb) << profile << " swap " << s;
    EXPECT_LT(jump, 45.0) << profile << " swap " << s;  // the swap is visible at all
  }
}

// A user's window/level stays across every swap (each stage is a new
// volume in the viewer, whose own window would otherwise come back), and
// the viewer's volume is named after the front end's label.
TEST(ZoomSwap, TheWindowAndTheLabelStayAcrossSwaps) {
  gpu::GlContext& ctx = test::gpuContext();
  auto volume = detailedVolume(128);
  auto source = std::make_shared<lod::InCoreMultiresSource>(volume);
  Explorer explorer(source, 64ull * 64 * 64);
  Viewer viewer(ctx, gpu::DeviceProfile::find("gles3"));
  viewer.setVolume(explorer.readLevel(1), "head");
  const ValueRange window{40.0, 180.0};
  viewer.setWindow(window);
  const lod::ZoomPolicyOptions options{.fadeMs = 0.0};
  ZoomSwap swap(ctx, explorer, zoomStagesFor(explorer, 1, kSize, options), options);
  swap.setLabel("head");
  gpu::Framebuffer fb = gpu::Framebuffer::create(ctx.ledger(), "zoom view", kSize, kSize,
                                                 gpu::rgba8For(ctx.caps().api));
  std::vector<std::string> names;
  for (const double zoom : {0.3, 0.5, 2.2}) {
    const double scale = swap.overviewZoom(viewer.camera()) / viewer.camera().zoom;
    viewer.camera().zoom = zoom / scale;
    swap.frame(viewer, kDtMs, kSize, kSize, fb.id());
    names.push_back(viewer.volumeName());
    EXPECT_EQ(viewer.window().min, window.min) << viewer.volumeName();
    EXPECT_EQ(viewer.window().max, window.max) << viewer.volumeName();
  }
  EXPECT_EQ(names, (std::vector<std::string>{"head (coarse level 2)", "head (medium level 1)",
                                             "head (native block)"}));
}

TEST(ZoomSwap, ThresholdsSwapLevelsAndTheFadeHasNoPopEs3) {
  checkFadeAndInstant(test::gpuContext(), "gles3");
}

TEST(ZoomSwap, ThresholdsSwapLevelsAndTheFadeHasNoPopEs2) {
  gpu::GlContext::Options o;
  o.api = gpu::ApiLevel::Gles2;
  auto ctx = gpu::GlContext::createHeadless(o);
  checkFadeAndInstant(*ctx, "webgl1");
  test::gpuContext();  // the shared context current again for later tests
}

}  // namespace
}  // namespace tessera::viewer
