// The session every front end drives: settings checked once with one range
// and message, state as versioned JSON that restores the same image, arrays
// handed over without a copy, streamed sources refined to the end, and every
// frame against the CPU reference.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/ExpectError.h"
#include "tessera/core/Error.h"
#include "tessera/io/Procedural.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/session/Session.h"

namespace tessera::session {
namespace {

std::string messageOf(const Settings& s) {
  try {
    s.validate();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SessionSettings, EachSettingHasOneRangeAndOneMessage) {
  Settings s;
  EXPECT_EQ(messageOf(s), "");
  s.render.stepVoxels = 0.0;
  EXPECT_EQ(messageOf(s), "step 0: expected voxels in (0, 8]");
  s.render.stepVoxels = 8.0;
  EXPECT_EQ(messageOf(s), "");
  s.render.stepVoxels = 8.5;
  EXPECT_EQ(messageOf(s), "step 8.5: expected voxels in (0, 8]");
  s = Settings();
  s.camera.fovYDeg = 180.0;
  EXPECT_EQ(messageOf(s), "fov 180: expected degrees in (0, 180)");
  s = Settings();
  s.render.sampling.maxMultiplier = 3;
  EXPECT_EQ(messageOf(s), "adaptive-max 3: expected a power of two in 1..64");
  s = Settings();
  s.window = ValueRange{10.0, 10.0};
  EXPECT_NE(messageOf(s).find("window 10 10"), std::string::npos);
  s = Settings();
  s.technique = "xray";
  EXPECT_NE(messageOf(s).find("technique 'xray': expected raycast"), std::string::npos);
  EXPECT_TRUE(kStepRange.contains(0.25) && !kStepRange.contains(0.0));
  EXPECT_EQ(kStepRange.text(), "(0, 8]");
}

TEST(SessionSettings, JsonRoundTripsEverySetting) {
  Settings s;
  s.technique = "slice3d";
  s.camera.azimuthDeg = 33.0;
  s.camera.projection = Projection::Orthographic;
  s.tf = TransferFunction::preset("ct-bone");
  s.window = ValueRange{-100.0, 300.0};
  s.render.mode = RenderMode::Mip;
  s.render.stepVoxels = 0.75;
  s.render.sampling.preintegrate = true;
  s.render.sampling.preintegrateLitOnly = true;
  s.render.shading.enabled = true;
  s.render.shading.headlight = false;
  s.render.shading.lightDirection = {0.0, 1.0, 0.0};
  s.render.clipping.planes.push_back({{0.0, 1.0, 0.0}, 5.0});
  s.render.clipping.cropMax = {1.0, 0.5, 1.0};
  s.lutSize = 256;
  const nlohmann::json j = s.toJson();
  EXPECT_EQ(j["version"], kSettingsVersion);
  const Settings back = Settings::fromJson(j);
  EXPECT_EQ(back.toJson(), j);
  EXPECT_EQ(back.render.clipping.planes.size(), 1u);
  EXPECT_EQ(back.window->min, -100.0);
}

TEST(SessionSettings, FromJsonRejectsOtherVersionsAndBadValuesByName) {
  nlohmann::json j = Settings().toJson();
  j["version"] = 99;
  EXPECT_THROW(Settings::fromJson(j), InputError);
  j["version"] = kSettingsVersion;
  j["step"] = -1.0;
  try {
    Settings::fromJson(j);
    FAIL() << "a negative step was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("step -1"), std::string::npos) << e.what();
  }
  j["step"] = "half";
  EXPECT_THROW(Settings::fromJson(j), InputError);
  j["step"] = 0.5;
  j["camera"]["azimuth"] = "left";
  EXPECT_EQ(test::inputErrorMessage([&] { Settings::fromJson(j); }),
            "settings.camera.azimuth is a string, expected a number");
  j["camera"]["azimuth"] = 10.0;
  j["background"][1] = true;
  EXPECT_EQ(test::inputErrorMessage([&] { Settings::fromJson(j); }),
            "settings.background[1] is true or false, expected a number");
}

TEST(Session, RendersAnArrayItWasHandedWithoutCopyingItAgainstTheReference) {
  Session s("native");
  auto volume = std::make_shared<Volume>(makeSphere({32, 32, 32}));
  const std::byte* voxels = volume->bytes().data();
  s.setVolume(volume, "sphere");
  EXPECT_EQ(s.volume().bytes().data(), voxels);  // the caller's buffer, not a copy
  s.settings().tf = TransferFunction::preset("grey");
  s.settings().render = RenderSettings();  // plain sampling: the reference takes every sample
  const Image image = s.render(96, 96);
  const Image reference = s.renderReference(96, 96);
  EXPECT_GT(psnr(image, reference), 40.0);
  EXPECT_GT(ssim(image, reference), 0.98);
}

TEST(Session, RestoredStateRendersTheSameImage) {
  Session a("native");
  a.open("gen:shepp-logan:32");
  a.settings().camera.azimuthDeg = 40.0;
  a.settings().camera.elevationDeg = 20.0;
  a.settings().render.mode = RenderMode::Mip;
  const Image first = a.render(64, 64);
  const nlohmann::json state = a.state();
  EXPECT_EQ(state["volume"]["name"], "gen:shepp-logan:32");

  Session b("native");
  b.open("gen:shepp-logan:32");
  b.restore(nlohmann::json::parse(state.dump()));
  const Image second = b.render(64, 64);
  ASSERT_EQ(first.rgba().size(), second.rgba().size());
  EXPECT_EQ(first.rgba(), second.rgba());
  Session c("native");
  c.open("gen:shepp-logan:32");
  EXPECT_NE(c.render(64, 64).rgba(), first.rgba());  // the state mattered
}

TEST(Session, StreamsAGeneratedHeadAndRefinesItToTheEnd) {
  Session s("native");
  s.settings().layout = "bricks";
  s.open("head:96x96x96");
  EXPECT_TRUE(s.streamed());
  EXPECT_THROW(s.volume(), InputError);
  RenderRequest r;
  r.settings = s.settings();
  r.width = 64;
  r.height = 64;
  const RenderResult result = s.run(r);
  ASSERT_TRUE(result.bricks.has_value());
  EXPECT_TRUE(result.bricks->complete);
  EXPECT_GE(result.bricks->refineFrames, 1);
  EXPECT_GT(result.bricks->bricksRead, 0u);
}

TEST(Session, RefusesBadSettingsAndKeepsTheOldOnes) {
  Session s("native");
  Settings bad;
  bad.render.stepVoxels = -2.0;
  EXPECT_THROW(s.setSettings(bad), InputError);
  EXPECT_EQ(s.settings().render.stepVoxels, kDefaultStepVoxels);
  EXPECT_THROW(s.render(8, 8), InputError);  // no volume yet: a message, not a crash
}

}  // namespace
}  // namespace tessera::session
