// Several channels rendered together (docs/channels.md): a 3-channel u16
// OME-Zarr store read with its omero defaults, the GPU ray caster over the
// channels packed into RGBA texels against the CPU reference, on ES 3 (3D
// textures) and ES 2 (mosaics), and a channel's toggle.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <memory>

#include <nlohmann/json.hpp>

#include "support/ChannelStore.h"
#include "support/ExpectError.h"
#include "support/GpuTestContext.h"
#include "support/TestCameras.h"
#include "support/TestSupport.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/io/ZarrChannels.h"
#include "tessera/layout/ChannelLayout.h"
#include "tessera/reference/ChannelReference.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/render/Raycaster.h"
#include "tessera/session/Settings.h"

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

class Channels : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDir>();
    test::writeChannelStore(dir_->path() / "three.ome.zarr");
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static std::string store() { return (dir_->path() / "three.ome.zarr").string(); }

  Image gpuImage(gpu::ApiLevel api, const ChannelSet& set, const Camera& camera,
                 const RenderSettings& settings, std::string* layoutName = nullptr) {
    test::ApiContext context(api);
    gpu::GlContext& gl = context.get();
    const gpu::DeviceLimits limits = gpu::DeviceLimits::of(gl.caps());
    auto layout = layout::ChannelLayout::create(set, limits, gl.ledger());
    if (layoutName) *layoutName = layout->plan().reason;
    render::Raycaster caster(gl, set.geometry(), *layout);
    caster.setSkipBlockSize(0);
    caster.setTransferFunction(channelRamp());
    RenderSettings channelFrame = settings;
    channelFrame.mode = renderModeFor(set.mode);
    return caster.renderImage(camera, channelFrame, kSize, kSize);
  }

  static std::unique_ptr<test::TempDir> dir_;
};

std::unique_ptr<test::TempDir> Channels::dir_;

TEST_F(Channels, ReadsEveryChannelWithOmeroDefaults) {
  const ChannelSet set = readZarrChannels(store());
  ASSERT_EQ(set.size(), 3);
  EXPECT_EQ(set[0].label, "sphere");
  EXPECT_EQ(set[2].label, "rod");
  EXPECT_EQ(set[0].color, glm::dvec3(1.0, 0.0, 0.0));
  EXPECT_NEAR(set[2].color.g, 128.0 / 255.0, 1e-6);
  EXPECT_EQ(set[1].window.min, 50.0);
  EXPECT_EQ(set[1].window.max, 2500.0);
  EXPECT_TRUE(set[2].visible);
  // Each channel holds its own structure: the rod's centre is in channel 2 only.
  const glm::ivec3 d = set.geometry().dims();
  const int x = static_cast<int>(0.72 * d.x), y = d.y / 2, z = static_cast<int>(0.45 * d.z);
  EXPECT_EQ(set[2].volume->valueAt(x, y, z), 4000.0);
  EXPECT_EQ(set[0].volume->valueAt(x, y, z), 100.0);

  const test::TempDir other;
  test::writeChannelStore(other / "inactive.ome.zarr", {.thirdActive = false});
  const ChannelSet chosen = readZarrChannels((other / "inactive.ome.zarr").string(), {2, 0});
  ASSERT_EQ(chosen.size(), 2);
  EXPECT_EQ(chosen[0].label, "rod");
  EXPECT_FALSE(chosen[0].visible);  // omero "active": false
  EXPECT_TRUE(chosen[1].visible);
}

TEST_F(Channels, RejectsBadChannelLists) {
  const std::string outside = test::inputErrorMessage([] { readZarrChannels(store(), {0, 3}); });
  EXPECT_NE(outside.find(store()), std::string::npos) << outside;
  EXPECT_NE(outside.find("channel 3 is outside the store's 3 channels"), std::string::npos)
      << outside;
  const std::string twice = test::inputErrorMessage([] { readZarrChannels(store(), {1, 1}); });
  EXPECT_NE(twice.find("channel 1 is chosen twice"), std::string::npos) << twice;
  EXPECT_EQ(test::inputErrorMessage([] { parseChannelList("0,x"); }),
            "--channels '0,x': 'x' is not a channel index (expected e.g. 0,2)");
  EXPECT_EQ(test::inputErrorMessage([] { parseChannelMode("sum"); }),
            "channel mode 'sum': expected additive or max");
  EXPECT_EQ(test::inputErrorMessage([] { parseHexColor("ff00"); }),
            "colour 'ff00': expected six hex digits RRGGBB");
}

TEST(ChannelSettings, ValidatedAndKeptInTheSessionState) {
  session::Settings s;
  s.channels.enabled = true;
  s.channels.indices = {0, 2};
  s.channels.colors = session::parseChannelColors("ff0000,00ff80");
  s.channels.windows = session::parseChannelWindows("100:2000,50:900");
  s.channels.visible = {true, false};
  s.channels.mode = ChannelMode::Max;
  const session::Settings back = session::Settings::fromJson(s.toJson());
  EXPECT_EQ(back.channels.indices, s.channels.indices);
  EXPECT_EQ(back.channels.colors, s.channels.colors);
  EXPECT_EQ(back.channels.windows[1].max, 900.0);
  EXPECT_EQ(back.channels.visible, s.channels.visible);
  EXPECT_EQ(back.channels.mode, ChannelMode::Max);
  EXPECT_FALSE(session::Settings().toJson().contains("channels"));

  s.channels.windows = session::parseChannelWindows("100:2000");
  EXPECT_EQ(test::inputErrorMessage([&] { s.validate(); }),
            "channels: 1 windows for 2 channels chosen");
  EXPECT_EQ(test::inputErrorMessage([] { session::parseChannelWindows("100:2000,9"); }),
            "--channel-windows '100:2000,9': '9' is not LO:HI (expected e.g. 100:2000,50:900)");
  s.channels.windows = session::parseChannelWindows("100:2000,900:50");
  EXPECT_EQ(test::inputErrorMessage([&] { s.validate(); }),
            "channel window 900:50: expected LO < HI");
}

TEST(ChannelSemantics, AdditiveSampleClampsToItsOpacity) {
  ChannelSet set;
  auto v = std::make_shared<Volume>(Volume::allocate({2, 2, 2}, ScalarType::U8));
  set.add({.volume = v, .label = "a", .color = {1, 0, 0}});
  set.add({.volume = v, .label = "b", .color = {1, 1, 0}});
  const double a[2] = {0.5, 0.5};
  const ChannelSample s = combineChannels(set, a);
  EXPECT_DOUBLE_EQ(s.alpha, 0.75);
  EXPECT_DOUBLE_EQ(s.premultiplied.r, 0.75);  // 1.0 clamped to the opacity
  EXPECT_DOUBLE_EQ(s.premultiplied.g, 0.5);
  EXPECT_DOUBLE_EQ(s.premultiplied.b, 0.0);
}

TEST_F(Channels, GpuEqualsReferenceOnTexture3dAndEs2) {
  ChannelSet set = readZarrChannels(store());
  const Camera camera = test::orbitCamera(set.geometry(), 30.0, 20.0);
  const RenderSettings settings = channelSettings();
  for (ChannelMode mode : {ChannelMode::Additive, ChannelMode::Max}) {
    set.mode = mode;
    const Image ref = renderChannelsReference(set, channelRamp(), camera, settings, kSize, kSize);
    for (gpu::ApiLevel api : {gpu::ApiLevel::Gles3, gpu::ApiLevel::Gles2}) {
      std::string how;
      const Image gpu = gpuImage(api, set, camera, settings, &how);
      const double db = psnr(gpu, ref);
      std::printf("channels %s on %s (%s): %.1f dB\n", channelModeName(mode), test::apiName(api),
                  how.c_str(), db);
      EXPECT_GE(db, 40.0) << channelModeName(mode) << " " << test::apiName(api) << " " << how;
    }
  }
}

// Six channels: two RGBA textures (channels 4 and 5 in the second), the
// same image on the GPU as in the reference.
TEST_F(Channels, SixChannelsInTwoTexturesEqualReference) {
  const ChannelSet three = readZarrChannels(store());
  ChannelSet six;
  const glm::dvec3 colors[6] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {0, 1, 1}, {1, 0, 1}};
  for (int i = 0; i < 6; ++i) {
    Channel c = three[i % 3];
    c.color = colors[i];
    c.label += std::to_string(i);
    if (i >= 3) c.window = {c.window.min, 0.5 * (c.window.min + c.window.max)};
    six.add(c);
  }
  six[1].visible = false;
  const Camera camera = test::orbitCamera(six.geometry(), -40.0, 10.0);
  const RenderSettings settings = channelSettings();
  const Image ref = renderChannelsReference(six, channelRamp(), camera, settings, kSize, kSize);
  for (gpu::ApiLevel api : {gpu::ApiLevel::Gles3, gpu::ApiLevel::Gles2}) {
    std::string how;
    const double db = psnr(gpuImage(api, six, camera, settings, &how), ref);
    std::printf("6 channels on %s (%s): %.1f dB\n", test::apiName(api), how.c_str(), db);
    EXPECT_GE(db, 40.0) << test::apiName(api);
  }
  // A seventh is refused.
  EXPECT_EQ(test::inputErrorMessage([&] { six.add(three[0], "store channel 6"); }),
            "store channel 6: at most 6 channels are rendered together");
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

TEST_F(Channels, TogglingAChannelChangesOnlyItsStructuresPixels) {
  ChannelSet set = readZarrChannels(store());
  const Camera camera = test::orbitCamera(set.geometry(), 30.0, 20.0);
  const RenderSettings settings = channelSettings();
  // Where the slab projects: the pixels a slab-only frame touches.
  ChannelSet slabOnly = set;
  slabOnly[0].visible = false;
  slabOnly[2].visible = false;
  const Image footprint =
      renderChannelsReference(slabOnly, channelRamp(), camera, settings, kSize, kSize);
  const Image black(kSize, kSize);
  const std::vector<bool> slab = changed(footprint, black, 0);

  const Image all = gpuImage(gpu::ApiLevel::Gles3, set, camera, settings);
  ChannelSet noSlab = set;
  noSlab[1].visible = false;
  const Image without = gpuImage(gpu::ApiLevel::Gles3, noSlab, camera, settings);
  const std::vector<bool> diff = changed(all, without, 1);
  int inside = 0, outside = 0;
  for (std::size_t i = 0; i < diff.size(); ++i) {
    if (!diff[i]) continue;
    (slab[i] ? inside : outside) += 1;
  }
  EXPECT_GT(inside, kSize * kSize / 20) << "the slab's pixels should change";
  EXPECT_EQ(outside, 0) << "pixels outside the slab's projection changed";
}

}  // namespace
}  // namespace tessera
