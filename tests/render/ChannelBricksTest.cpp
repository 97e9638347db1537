// Several channels in the bricks layout (docs/channels.md "Layouts"): one
// page table, each brick's channels packed four a RGBA texel (RGBA16 3D on
// ES 3, RGBA8 mosaic on ES 2), streamed and refined like one volume; the GPU
// image against the CPU reference of the level shown, a channel's toggle,
// six channels in two atlases, and the layouts that cannot draw channels.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <set>

#include "support/ChannelBricks.h"
#include "support/ChannelStore.h"
#include "support/ExpectError.h"
#include "support/GpuTestContext.h"
#include "support/TestCameras.h"
#include "support/TestSupport.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/DeviceSession.h"
#include "tessera/io/ZarrChannels.h"
#include "tessera/layout/BricksLayout.h"
#include "tessera/layout/ChannelLayouts.h"
#include "tessera/reference/ChannelReference.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/render/Raycaster.h"
#include "tessera/session/Session.h"

namespace tessera {
namespace {

constexpr int kSize = 128;

TransferFunction channelRamp() {
  TransferFunction tf;
  tf.addColor(0.0, {1.0, 1.0, 1.0});
  tf.addOpacity(0.0, 0.0);
  tf.addOpacity(0.1, 0.0);
  tf.addOpacity(1.0, 0.35);
  return tf;
}

RenderSettings channelSettings() {
  RenderSettings s;
  s.background = {0.0, 0.0, 0.0, 1.0};
  return s;
}

std::vector<std::shared_ptr<const lod::MultiresSource>> pyramids(const ChannelSet& set) {
  return test::channelPyramids(set);
}

struct BricksImage {
  Image image;
  std::string plan;
  std::vector<int> cellsPerLevel;
};

// The refined frame of the channels through BricksLayout::createChannels
// (16^3 bricks: 6 x 6 x 3 cells) over `shown`, one image for each of
// `sets` (the same channels, other mode or visibility) copied into it.
std::vector<BricksImage> bricksImages(gpu::ApiLevel api, ChannelSet& shown,
                                      const std::vector<const ChannelSet*>& sets,
                                      const Camera& camera) {
  test::ApiContext context(api);
  gpu::GlContext& gl = context.get();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(gl.caps());
  auto layout = layout::BricksLayout::createChannels(pyramids(shown), shown, limits, gl.ledger(),
                                                     {.brickSize = 16, .workers = 0});
  render::Raycaster caster(gl, shown.geometry(), *layout);
  caster.setSkipBlockSize(0);
  caster.setTransferFunction(channelRamp());
  std::vector<BricksImage> out;
  for (const ChannelSet* set : sets) {
    shown = *set;  // the layout reads windows, colours and visibility from it
    layout::BricksFrame f;
    for (int i = 0; i < 100 && !f.complete; ++i)
      f = layout->update(camera, kSize, kSize, channelRamp());
    EXPECT_TRUE(f.complete);
    RenderSettings s = channelSettings();
    s.mode = renderModeFor(shown.mode);
    out.push_back(
        {caster.renderImage(camera, s, kSize, kSize), layout->plan().reason, f.cellsPerLevel});
  }
  return out;
}

class ChannelBricks : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDir>();
    test::writeChannelStore(dir_->path() / "three.ome.zarr");
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static std::string store() { return (dir_->path() / "three.ome.zarr").string(); }
  static std::unique_ptr<test::TempDir> dir_;
};

std::unique_ptr<test::TempDir> ChannelBricks::dir_;

// 96 voxels across 128 pixels: level 0 wherever a channel shows, so the
// reference is the channels' own trilinear field.
TEST_F(ChannelBricks, GpuEqualsReferenceOnEs3AndEs2) {
  ChannelSet set = readZarrChannels(store());
  const Camera camera = test::orbitCamera(set.geometry(), 30.0, 20.0);
  for (gpu::ApiLevel api : {gpu::ApiLevel::Gles3, gpu::ApiLevel::Gles2}) {
    ChannelSet additive = set, max = set;
    max.mode = ChannelMode::Max;
    ChannelSet shown = additive;
    const std::vector<BricksImage> images = bricksImages(api, shown, {&additive, &max}, camera);
    for (std::size_t i = 0; i < images.size(); ++i) {
      const ChannelSet& s = i == 0 ? additive : max;
      const Image ref =
          renderChannelsReference(s, channelRamp(), camera, channelSettings(), kSize, kSize);
      const double db = psnr(images[i].image, ref);
      std::printf("channel bricks %s on %s (%s): %.1f dB\n", channelModeName(s.mode),
                  test::apiName(api), images[i].plan.c_str(), db);
      EXPECT_GE(db, 40.0) << channelModeName(s.mode) << " " << test::apiName(api);
      // Level 0 where the channels show; cells no visible channel shows
      // fall back to a coarser brick (not fetched).
      ASSERT_GE(images[i].cellsPerLevel.size(), 2u);
      EXPECT_GT(images[i].cellsPerLevel[0], 0);
    }
  }
}

// An atlas of about 40 slots holds a third of the 108 level-0 bricks the
// view wants: the frame shows level 0 in some cells and level 1 in the
// rest, and equals the reference that reads each cell's level (not the
// level-0 reference: the levels differ at the structures' edges).
TEST_F(ChannelBricks, MixedLevelFrameEqualsTheReferenceOfItsLevels) {
  ChannelSet set = readZarrChannels(store());
  const Camera camera = test::orbitCamera(set.geometry(), 30.0, 20.0);
  for (gpu::ApiLevel api : {gpu::ApiLevel::Gles3, gpu::ApiLevel::Gles2}) {
    for (ChannelMode mode : {ChannelMode::Additive, ChannelMode::Max}) {
      ChannelSet shown = set;
      shown.mode = mode;
      test::ApiContext context(api);
      gpu::GlContext& gl = context.get();
      const gpu::DeviceLimits limits = gpu::DeviceLimits::of(gl.caps());
      const std::uint64_t slot = 18 * 18 * 18 * (api == gpu::ApiLevel::Gles3 ? 8 : 4);
      auto layout = layout::BricksLayout::createChannels(
          pyramids(shown), shown, limits, gl.ledger(),
          {.brickSize = 16, .atlasBytesCap = 40 * slot, .workers = 0});
      render::Raycaster caster(gl, shown.geometry(), *layout);
      caster.setSkipBlockSize(0);
      caster.setTransferFunction(channelRamp());
      layout::BricksFrame f;
      for (int i = 0; i < 100 && !f.complete; ++i)
        f = layout->update(camera, kSize, kSize, channelRamp());
      RenderSettings s = channelSettings();
      s.mode = renderModeFor(mode);
      const Image image = caster.renderImage(camera, s, kSize, kSize);
      const ChannelLevels levels = test::channelLevelsShown(shown, *layout);
      ASSERT_TRUE(levels.cells.mixed()) << layout->plan().reason;
      const std::vector<int> n = levels.cells.cellsPerLevel();
      const double mixed = psnr(image, renderChannelsReference(shown, levels, channelRamp(), camera,
                                                               channelSettings(), kSize, kSize));
      const double level0 = psnr(image, renderChannelsReference(shown, channelRamp(), camera,
                                                                channelSettings(), kSize, kSize));
      std::printf(
          "mixed-level channel bricks %s on %s (%d slots, cells L0 %d L1 %d L2 %d): "
          "%.1f dB against its levels, %.1f dB against level 0\n",
          channelModeName(mode), test::apiName(api), layout->slotCount(), n[0],
          n.size() > 2 ? n[1] : 0, n.size() > 3 ? n[2] : 0, mixed, level0);
      EXPECT_GT(n[0], 0);
      EXPECT_GE(mixed, 40.0) << channelModeName(mode) << " " << test::apiName(api);
      EXPECT_GT(mixed, level0 + 3.0) << "the level-0 reference should not fit a mixed frame";
    }
  }
}

// Pixels where a and b differ by more than `tolerance` in any component.
std::vector<bool> changed(const Image& a, const Image& b, int tolerance) {
  std::vector<bool> out(static_cast<std::size_t>(a.width()) * a.height());
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) {
      bool diff = false;
      for (int c = 0; c < 3; ++c)
        diff = diff || std::abs(a.pixel(x, y)[c] - b.pixel(x, y)[c]) > tolerance;
      out[static_cast<std::size_t>(y) * a.width() + x] = diff;
    }
  }
  return out;
}

// Hiding the slab on the same layout (nothing re-uploaded) changes only
// the pixels where the slab projects.
TEST_F(ChannelBricks, TogglingAChannelChangesOnlyItsStructuresPixels) {
  ChannelSet set = readZarrChannels(store());
  const Camera camera = test::orbitCamera(set.geometry(), 30.0, 20.0);
  ChannelSet slabOnly = set;
  slabOnly[0].visible = false;
  slabOnly[2].visible = false;
  const Image footprint =
      renderChannelsReference(slabOnly, channelRamp(), camera, channelSettings(), kSize, kSize);
  const std::vector<bool> slab = changed(footprint, Image(kSize, kSize), 0);
  ChannelSet all = set, noSlab = set;
  noSlab[1].visible = false;
  ChannelSet shown = all;
  const std::vector<BricksImage> images =
      bricksImages(gpu::ApiLevel::Gles3, shown, {&all, &noSlab}, camera);
  const std::vector<bool> diff = changed(images[0].image, images[1].image, 1);
  int inside = 0, outside = 0;
  for (std::size_t i = 0; i < diff.size(); ++i) {
    if (diff[i]) (slab[i] ? inside : outside) += 1;
  }
  std::printf("hiding the slab: %d pixels changed inside its projection, %d outside\n", inside,
              outside);
  EXPECT_GT(inside, kSize * kSize / 20) << "the slab's pixels should change";
  EXPECT_EQ(outside, 0) << "pixels outside the slab's projection changed";
}

// Six channels: channels 4 and 5 in a second atlas at the same slots.
TEST_F(ChannelBricks, SixChannelsInTwoAtlasesEqualReference) {
  const ChannelSet three = readZarrChannels(store());
  ChannelSet six;
  const glm::dvec3 colors[6] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {0, 1, 1}, {1, 0, 1}};
  for (int i = 0; i < 6; ++i) {
    Channel c = three[i % 3];
    c.color = colors[i];
    if (i >= 3) c.window = {c.window.min, 0.5 * (c.window.min + c.window.max)};
    six.add(c);
  }
  six[1].visible = false;
  const Camera camera = test::orbitCamera(six.geometry(), -40.0, 10.0);
  const Image ref =
      renderChannelsReference(six, channelRamp(), camera, channelSettings(), kSize, kSize);
  ChannelSet shown = six;
  const std::vector<BricksImage> images = bricksImages(gpu::ApiLevel::Gles3, shown, {&six}, camera);
  const double db = psnr(images[0].image, ref);
  std::printf("6 channel bricks (%s): %.1f dB\n", images[0].plan.c_str(), db);
  EXPECT_GE(db, 40.0);
  EXPECT_NE(images[0].plan.find("6 channels of"), std::string::npos) << images[0].plan;
}

// --layout bricks streams channels; texture3d draws them in core; a layout
// that cannot draw channels is refused, naming the ones that can.
TEST_F(ChannelBricks, LayoutWishIsHonouredOrRefused) {
  const ChannelSet set = readZarrChannels(store());
  test::ApiContext context(gpu::ApiLevel::Gles3);
  gpu::GlContext& gl = context.get();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(gl.caps());
  int opened = 0;
  const layout::ChannelSources sources = [&] {
    ++opened;
    return pyramids(set);
  };
  const auto bricks = layout::createChannelLayout("bricks", set, sources, limits, gl.ledger());
  EXPECT_NE(bricks->streaming(), nullptr);
  EXPECT_EQ(bricks->name(), "bricks");
  const auto inCore = layout::createChannelLayout("auto", set, sources, limits, gl.ledger());
  EXPECT_EQ(inCore->streaming(), nullptr);
  EXPECT_EQ(inCore->name(), "texture3d");
  EXPECT_EQ(opened, 1);  // only bricks open the sources
  EXPECT_EQ(test::inputErrorMessage(
                [&] { layout::createChannelLayout("fcc", set, sources, limits, gl.ledger()); }),
            "--layout fcc cannot draw channels on " + limits.profile +
                ": channel frames draw in texture3d or bricks");
}

// ES 2 names a slot by mosaic and 8-bit place (255 slots a mosaic): on a
// WebGL 1 profile of 16 units and an iPad 2 of 8, three channels in 8^3
// bricks (864 at level 0) spread over several mosaics, more than 255 slots
// are resident and addressed (cells reading mosaic 2 and up), and the image
// equals the reference.
TEST_F(ChannelBricks, Es2ProfilesAddressMoreThan255SlotsPerGroup) {
  const ChannelSet set = readZarrChannels(store());
  const Camera camera = test::orbitCamera(set.geometry(), 30.0, 20.0);
  const Image ref =
      renderChannelsReference(set, channelRamp(), camera, channelSettings(), kSize, kSize);
  for (const char* profile : {"webgl1-desktop-2012", "ipad2"}) {
    const test::BudgetOverride keep(HostBudget::global().limitBytes());
    gpu::DeviceSession device = gpu::openDevice(profile);
    ChannelSet shown = set;
    auto layout = layout::BricksLayout::createChannels(pyramids(shown), shown, device.limits,
                                                       device.context->ledger(),
                                                       {.brickSize = 8, .workers = 0});
    render::Raycaster caster(*device.context, shown.geometry(), *layout);
    caster.setSkipBlockSize(0);
    caster.setTransferFunction(channelRamp());
    layout::BricksFrame f;
    for (int i = 0; i < 200 && !f.complete; ++i)
      f = layout->update(camera, kSize, kSize, channelRamp());
    EXPECT_TRUE(f.complete) << profile;
    const Image image = caster.renderImage(camera, channelSettings(), kSize, kSize);
    const double db = psnr(image, ref);
    // Which mosaics the page table names, and the slots its cells read.
    std::set<int> mosaics;
    std::set<std::pair<int, int>> slots;
    const glm::ivec3 cells = layout->grid().bricks(0);
    for (int z = 0; z < cells.z; ++z) {
      for (int y = 0; y < cells.y; ++y) {
        for (int x = 0; x < cells.x; ++x) {
          const auto at = layout->lookup((glm::dvec3(x, y, z) + 0.5) * 8.0);
          if (at.level < 0) continue;
          mosaics.insert(at.texture);
          slots.insert({at.texture, static_cast<int>(at.texel.z) / 10});
        }
      }
    }
    std::printf(
        "ES 2 channel bricks on %s: %d slots, %d wanted, %zu distinct slots read by the "
        "cells, mosaics up to %d, %.1f dB (%s)\n",
        profile, layout->slotCount(), f.wanted, slots.size(), *mosaics.rbegin(), db,
        layout->plan().reason.c_str());
    EXPECT_GT(layout->slotCount(), 255) << layout->plan().reason;
    EXPECT_GT(f.wanted, 255) << profile;
    EXPECT_GT(static_cast<int>(slots.size()), 255) << profile;
    EXPECT_GE(*mosaics.rbegin(), 1) << profile;
    EXPECT_NE(layout->plan().reason.find("slots named by mosaic and place"), std::string::npos)
        << layout->plan().reason;
    EXPECT_GE(db, 40.0) << profile;
  }
}

// The brick walk: one page read per brick cell a ray enters, every channel
// of the cell's samples read from that slot. Its images equal the page
// read per sample (walk false) and the reference, additive and max, ES 3
// and ES 2; the frame times of the two alternate (printed, not asserted).
TEST_F(ChannelBricks, BrickWalkEqualsPerSampleLookup) {
  const ChannelSet set = readZarrChannels(store());
  const Camera camera = test::orbitCamera(set.geometry(), 30.0, 20.0);
  for (gpu::ApiLevel api : {gpu::ApiLevel::Gles3, gpu::ApiLevel::Gles2}) {
    test::ApiContext context(api);
    gpu::GlContext& gl = context.get();
    const gpu::DeviceLimits limits = gpu::DeviceLimits::of(gl.caps());
    for (ChannelMode mode : {ChannelMode::Additive, ChannelMode::Max}) {
      ChannelSet shown = set;
      shown.mode = mode;
      RenderSettings s = channelSettings();
      s.mode = renderModeFor(mode);
      const Image ref = renderChannelsReference(shown, channelRamp(), camera, s, kSize, kSize);
      Image images[2];
      double ms[2] = {0.0, 0.0};
      std::vector<std::unique_ptr<layout::BricksLayout>> layouts;
      std::vector<std::unique_ptr<render::Raycaster>> casters;
      for (const bool walk : {false, true}) {
        layouts.push_back(
            layout::BricksLayout::createChannels(pyramids(shown), shown, limits, gl.ledger(),
                                                 {.brickSize = 16, .workers = 0, .walk = walk}));
        EXPECT_EQ(layouts.back()->walksBricks(), walk);
        layout::BricksFrame f;
        for (int i = 0; i < 100 && !f.complete; ++i)
          f = layouts.back()->update(camera, kSize, kSize, channelRamp());
        casters.push_back(
            std::make_unique<render::Raycaster>(gl, shown.geometry(), *layouts.back()));
        casters.back()->setSkipBlockSize(0);
        casters.back()->setTransferFunction(channelRamp());
      }
      for (int round = 0; round < 3; ++round) {
        for (int w = 0; w < 2; ++w) {
          const auto t0 = std::chrono::steady_clock::now();
          images[w] = casters[static_cast<std::size_t>(w)]->renderImage(camera, s, kSize, kSize);
          const double t =
              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                  .count();
          if (round > 0) ms[w] += t / 2.0;  // round 0 compiles
        }
      }
      const double walkVsLookup = psnr(images[1], images[0]);
      const double walkVsRef = psnr(images[1], ref), lookupVsRef = psnr(images[0], ref);
      std::printf(
          "channel brick walk %s on %s: walked vs per-sample %.1f dB, vs reference %.1f dB "
          "(per-sample %.1f dB); %.1f ms per-sample, %.1f ms walked\n",
          channelModeName(mode), test::apiName(api), walkVsLookup, walkVsRef, lookupVsRef, ms[0],
          ms[1]);
      EXPECT_GE(walkVsLookup, 50.0) << channelModeName(mode) << " " << test::apiName(api);
      EXPECT_GE(walkVsRef, 40.0) << channelModeName(mode) << " " << test::apiName(api);
    }
  }
}

// Not a test: the frame-time bench of the walk (docs/channels.md), run on a
// store of bench/channels_store.py by
//   TESSERA_CHANNEL_WALK_BENCH=STORE test_render --gtest_filter=*ChannelWalkBench*
// Per API and mode, frames of the per-sample lookup and of the walk
// alternate (5 each, 384x384, after one that compiles); prints the medians.
TEST(ChannelWalkBench, AlternatingFrames) {
  const char* path = std::getenv("TESSERA_CHANNEL_WALK_BENCH");
  if (!path) GTEST_SKIP() << "set TESSERA_CHANNEL_WALK_BENCH=STORE to run the bench";
  const ChannelSet set = readZarrChannels(path);
  const Camera camera = test::orbitCamera(set.geometry(), 30.0, 20.0);
  constexpr int kPixels = 384, kFrames = 5;
  for (gpu::ApiLevel api : {gpu::ApiLevel::Gles3, gpu::ApiLevel::Gles2}) {
    test::ApiContext context(api);
    gpu::GlContext& gl = context.get();
    const gpu::DeviceLimits limits = gpu::DeviceLimits::of(gl.caps());
    for (ChannelMode mode : {ChannelMode::Additive, ChannelMode::Max}) {
      ChannelSet shown = set;
      shown.mode = mode;
      RenderSettings s = channelSettings();
      s.mode = renderModeFor(mode);
      std::vector<std::unique_ptr<layout::BricksLayout>> layouts;
      std::vector<std::unique_ptr<render::Raycaster>> casters;
      for (const bool walk : {false, true}) {
        layouts.push_back(layout::BricksLayout::createChannels(pyramids(shown), shown, limits,
                                                               gl.ledger(), {.walk = walk}));
        layout::BricksFrame f;
        for (int i = 0; i < 2000 && !f.complete; ++i) {
          f = layouts.back()->update(camera, kPixels, kPixels, channelRamp());
          if (!f.complete) layouts.back()->waitForBricks(20.0);
        }
        casters.push_back(
            std::make_unique<render::Raycaster>(gl, shown.geometry(), *layouts.back()));
        casters.back()->setSkipBlockSize(0);
        casters.back()->setTransferFunction(channelRamp());
      }
      std::vector<double> ms[2];
      Image images[2];
      for (int round = 0; round <= kFrames; ++round) {
        for (int w = 0; w < 2; ++w) {
          const auto t0 = std::chrono::steady_clock::now();
          images[w] =
              casters[static_cast<std::size_t>(w)]->renderImage(camera, s, kPixels, kPixels);
          const double t =
              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                  .count();
          if (round > 0) ms[w].push_back(t);
        }
      }
      for (auto& m : ms) std::sort(m.begin(), m.end());
      std::printf(
          "channel walk bench %s %s %dx%d (%s): per-sample lookup median %.1f ms, walked "
          "median %.1f ms (%.2fx); walked vs per-sample %.1f dB\n",
          channelModeName(mode), test::apiName(api), kPixels, kPixels,
          layouts[1]->plan().reason.c_str(), ms[0][kFrames / 2], ms[1][kFrames / 2],
          ms[0][kFrames / 2] / ms[1][kFrames / 2], psnr(images[1], images[0]));
    }
  }
}

// Through the session (what `render --channels ... --layout L` runs): the
// wish reaches the channel frame, and a refused one is the user's message.
TEST_F(ChannelBricks, SessionHonoursTheLayoutWish) {
  session::Session session;
  session.settings().channels.enabled = true;
  session.settings().layout = "bricks";
  const session::ChannelFrame f = session.renderChannels(store(), 64, 64, true);
  EXPECT_NE(f.layout.find("^3 bricks (+1 voxel apron)"), std::string::npos) << f.layout;
  EXPECT_GE(f.psnr, 40.0) << f.layout;
  session.settings().layout = "fcc";
  EXPECT_EQ(test::inputErrorMessage([&] { session.renderChannels(store(), 64, 64, false); }),
            "--layout fcc cannot draw channels on native: channel frames draw in texture3d or "
            "bricks");
}

}  // namespace
}  // namespace tessera
