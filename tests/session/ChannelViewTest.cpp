// The channel lists' API (session/ChannelView.h), what the desktop viewer's
// and the page's panels call: its frame equals the one `tessera render
// STORE --channels ... --channel-colors ... --channel-windows ...` draws
// (Session::renderChannels with the settings the CLI parses), an edit is
// kept in the session's state, and a toggle changes only that channel's
// pixels.
#include <gtest/gtest.h>

#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "support/ChannelStore.h"
#include "support/ExpectError.h"
#include "support/TestSupport.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/session/Session.h"

namespace tessera::session {
namespace {

constexpr int kSize = 96;

// The look both sessions share: the CLI's defaults but for a grey TF with a
// visible opacity (docs/channels.md renders with --tf grey --opacity-scale 20).
void look(Settings& s) {
  s.tf = TransferFunction::preset("grey");
  s.render.opacityScale = 20.0;
  s.camera.azimuthDeg = 30.0;
  s.camera.elevationDeg = 20.0;
}

// What `tessera render STORE --channel-colors C --channel-windows W
// --channel-visible V` renders (the CLI's parsing, a fresh session).
Image cliFrame(const std::string& store, const std::string& colors, const std::string& windows,
               std::vector<bool> visible) {
  Session cli("native");
  look(cli.settings());
  ChannelSettings& c = cli.settings().channels;
  c.enabled = true;
  c.colors = parseChannelColors(colors);
  c.windows = parseChannelWindows(windows);
  c.visible = std::move(visible);
  return cli.renderChannels(store, kSize, kSize, false).image;
}

class ChannelViewTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDir>();
    test::writeChannelStore(dir_->path() / "three.ome.zarr", {.dims = {48, 48, 24}});
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static std::string store() { return (dir_->path() / "three.ome.zarr").string(); }
  static std::unique_ptr<test::TempDir> dir_;
};
std::unique_ptr<test::TempDir> ChannelViewTest::dir_;

TEST_F(ChannelViewTest, EditsRenderAsTheCommandLineDoesAndStayInTheState) {
  Session s("native");
  look(s.settings());
  ChannelView& view = s.channelView();
  ASSERT_TRUE(view.open(store()));
  ASSERT_EQ(view.channels().size(), 3);
  EXPECT_EQ(view.channels()[1].label, "slab");
  view.render(kSize, kSize);
  const Image defaults = view.readImage();
  const Image cliDefaults =
      cliFrame(store(), "ff0000,00ff00,0080ff", "100:3000,50:2500,100:4000", {true, true, true});
  EXPECT_GE(psnr(defaults, cliDefaults), 40.0);

  // The panel's edits: the slab off, the sphere yellow, the rod's window narrowed.
  view.setVisible(1, false);
  view.setColor(0, {1.0, 1.0, 0.0});
  view.setWindow(2, {100.0, 2000.0});
  view.render(kSize, kSize);
  const Image edited = view.readImage();
  const Image cliEdited =
      cliFrame(store(), "ffff00,00ff00,0080ff", "100:3000,50:2500,100:2000", {true, false, true});
  const double db = psnr(edited, cliEdited);
  EXPECT_GE(db, 40.0);
  EXPECT_LT(psnr(edited, defaults), 40.0);  // the edits show
  std::printf("channel view vs CLI: defaults %.1f dB, edited %.1f dB\n",
              psnr(defaults, cliDefaults), db);

  const nlohmann::json channels = s.state()["settings"]["channels"];
  EXPECT_EQ(channels["visible"], nlohmann::json({true, false, true}));
  EXPECT_EQ(channels["windows"][2], nlohmann::json({100.0, 2000.0}));
}

TEST_F(ChannelViewTest, ToggleChangesOnlyThatChannelsPixels) {
  Session s("native");
  look(s.settings());
  ChannelView& view = s.channelView();
  ASSERT_TRUE(view.open(store()));
  view.render(kSize, kSize);
  const Image all = view.readImage();
  view.setVisible(1, false);
  view.render(kSize, kSize);
  const Image withoutSlab = view.readImage();
  // The slab alone: where it shows at all.
  view.setVisible(0, false);
  view.setVisible(2, false);
  view.setVisible(1, true);
  view.render(kSize, kSize);
  const Image slabAlone = view.readImage();
  const Image black =
      cliFrame(store(), "000000,000000,000000", "100:3000,50:2500,100:4000", {false, false, false});
  const std::vector<bool> changed = test::differing(all, withoutSlab, 2);
  const std::vector<bool> slab = test::differing(slabAlone, black, 0);
  int inside = 0, outside = 0;
  for (std::size_t p = 0; p < changed.size(); ++p) {
    if (changed[p]) ++(slab[p] ? inside : outside);
  }
  std::printf("slab toggled: %d pixels changed inside its projection, %d outside\n", inside,
              outside);
  EXPECT_GT(inside, kSize * kSize / 20);
  EXPECT_EQ(outside, 0);
}

// The view draws with the technique the settings (the viewer's menu) name,
// as `tessera render STORE --channels ... --technique X` does, on ES 3 and an
// ES 2 profile; a change of technique in the same view makes the new one.
TEST_F(ChannelViewTest, DrawsTheTechniqueTheSettingsName) {
  for (const char* profile : {"native", "webgl1-desktop-2012"}) {
    Session s(profile);
    look(s.settings());
    ChannelView& view = s.channelView();
    ASSERT_TRUE(view.open(store()));
    view.setVisible(2, false);
    for (const char* technique : {"slice2d", "raycast", "slice3d"}) {
      s.settings().technique = technique;
      view.render(kSize, kSize);
      const Image image = view.readImage();
      Session cli(profile);
      look(cli.settings());
      cli.settings().technique = technique;
      ChannelSettings& c = cli.settings().channels;
      c.enabled = true;
      c.visible = {true, true, false};
      const ChannelFrame f = cli.renderChannels(store(), kSize, kSize, true);
      const double db = psnr(image, f.image);
      std::printf(
          "channel view %s on %s: %.1f dB against the CLI's frame (%.1f dB against "
          "the reference)\n",
          technique, profile, db, psnr(image, *f.reference));
      EXPECT_GE(db, 99.0) << technique << " " << profile;
      EXPECT_GE(psnr(image, *f.reference), 40.0) << technique << " " << profile;
    }
  }
}

// A front end whose GPU context was lost (the page's WebGL on a phone)
// takes the channels out of the session on the lost context and shows them
// in one made on the restored context: the same frame, the edits kept, the
// voxels not read again (the first view is closed).
TEST_F(ChannelViewTest, ChannelsTakenOutShowTheSameFrameInAnotherSession) {
  Session lost("native");
  look(lost.settings());
  ASSERT_TRUE(lost.channelView().open(store()));
  lost.channelView().setVisible(1, false);
  lost.channelView().setColor(0, {1.0, 1.0, 0.0});
  lost.channelView().setWindow(2, {100.0, 2000.0});
  lost.channelView().render(kSize, kSize);
  const Image before = lost.channelView().readImage();
  const nlohmann::json state = lost.state();
  std::optional<ChannelView::Shown> shown = lost.channelView().takeShown();
  ASSERT_TRUE(shown.has_value());
  EXPECT_FALSE(lost.channelView().isOpen());
  EXPECT_FALSE(lost.channelView().takeShown().has_value());

  Session restored("native");
  restored.restore({{"version", state["version"]}, {"settings", state["settings"]}});
  restored.channelView().show(std::move(shown->set), shown->name);
  ASSERT_TRUE(restored.channelView().isOpen());
  EXPECT_EQ(restored.channelView().name(), store());
  EXPECT_FALSE(restored.channelView().channels()[1].visible);
  EXPECT_EQ(restored.channelView().channels()[2].window.max, 2000.0);
  restored.channelView().render(kSize, kSize);
  const double db = psnr(restored.channelView().readImage(), before);
  std::printf("channels taken out and shown in another session: %.1f dB\n", db);
  EXPECT_GE(db, 60.0);
  EXPECT_EQ(restored.state()["settings"]["channels"], state["settings"]["channels"]);
}

// A volume opened while a store's channels are shown replaces them, in
// the view too (the desktop's Open and drop used to keep showing the
// store's channels over the new volume): the frame is the new volume's.
TEST_F(ChannelViewTest, AnotherVolumeOpenedReplacesTheChannels) {
  for (const bool inView : {false, true}) {
    Session s("native");
    look(s.settings());
    ASSERT_TRUE(s.channelView().open(store()));
    ASSERT_TRUE(s.settings().channels.enabled);
    if (inView) {
      s.openInView("gen:shepp-logan:32");
    } else {
      s.open("gen:shepp-logan:32");
    }
    EXPECT_FALSE(s.channelView().isOpen()) << "inView " << inView;
    EXPECT_FALSE(s.settings().channels.enabled) << "inView " << inView;
    Session fresh("native");
    look(fresh.settings());
    if (inView) {
      fresh.openInView("gen:shepp-logan:32");
    } else {
      fresh.open("gen:shepp-logan:32");
    }
    const double db = psnr(s.render(kSize, kSize), fresh.render(kSize, kSize));
    std::printf("after the store's channels, %s: %.1f dB against a fresh session\n",
                inView ? "openInView" : "open", db);
    EXPECT_GE(db, 99.0) << "inView " << inView;
  }
}

TEST_F(ChannelViewTest, RefusesWhatTheSettingsRefuse) {
  Session s("native");
  ChannelView& view = s.channelView();
  EXPECT_FALSE(view.open("gen:sphere:16"));  // not a store: nothing to list
  EXPECT_FALSE(view.isOpen());
  ASSERT_TRUE(view.open(store()));
  EXPECT_EQ(test::inputErrorMessage([&] { view.setVisible(3, false); }),
            store() + ": channel 3 is outside the 3 channels shown (0..2)");
  EXPECT_NE(test::inputErrorMessage([&] {
              view.setWindow(0, {5.0, 5.0});
            }).find("expected LO < HI"),
            std::string::npos);
  EXPECT_NE(test::inputErrorMessage([&] {
              view.setColor(0, {1.5, 0.0, 0.0});
            }).find("0..1"),
            std::string::npos);
  view.close();
  EXPECT_FALSE(s.settings().channels.enabled);
}

}  // namespace
}  // namespace tessera::session
