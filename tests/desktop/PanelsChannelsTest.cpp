// The desktop viewer's channel list (frontends/desktop/PanelsChannels.cpp),
// drawn in an ImGui context without a window (HeadlessImGui.h) and clicked
// as a user would: a visibility checkbox hides its channel and the next
// frame changes only that channel's pixels; a window typed into and one
// dragged, a colour typed into the swatch's picker and the mode's menu set
// the channel view as `tessera render STORE --channel-windows ...
// --channel-colors ...` renders it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "desktop/HeadlessImGui.h"
#include "desktop/Panels.h"
#include "desktop/RecordingHost.h"
#include "support/ChannelStore.h"
#include "support/TestSupport.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/session/Session.h"

namespace tessera::desktop {
namespace {

using test::HeadlessImGui;
constexpr int kSize = 96;

// The look of docs/channels.md (--tf grey --opacity-scale 20), as in
// tests/session/ChannelViewTest.cpp.
void look(session::Settings& s) {
  s.tf = TransferFunction::preset("grey");
  s.render.opacityScale = 20.0;
  s.camera.azimuthDeg = 30.0;
  s.camera.elevationDeg = 20.0;
}

// What `tessera render STORE --channel-colors C --channel-windows W
// --channel-visible V [--channel-mode max]` renders (a fresh session).
Image cliFrame(const std::string& store, const std::string& colors, const std::string& windows,
               ChannelMode mode = ChannelMode::Additive) {
  session::Session cli("native");
  look(cli.settings());
  session::ChannelSettings& c = cli.settings().channels;
  c.enabled = true;
  c.colors = session::parseChannelColors(colors);
  c.windows = session::parseChannelWindows(windows);
  c.mode = mode;
  return cli.renderChannels(store, kSize, kSize, false).image;
}

int count(const std::vector<bool>& pixels) {
  int n = 0;
  for (bool p : pixels) n += p ? 1 : 0;
  return n;
}

class PanelsChannels : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDir>();
    test::writeChannelStore(dir_->path() / "three.ome.zarr", {.dims = {48, 48, 24}});
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static std::string store() { return (dir_->path() / "three.ome.zarr").string(); }

  void SetUp() override {
    look(s.settings());
    ASSERT_TRUE(s.channelView().open(store()));
    ui.frame();
  }
  session::ChannelView& view() { return s.channelView(); }
  // The frame the 3D view shows next (DesktopApp's drawChannelView).
  Image nextFrame() {
    view().render(kSize, kSize);
    return view().readImage();
  }
  void clickVisible(int channel) { ui.click(kPanelTitle, {channel, "##visible"}); }

  session::Session s{"native"};
  test::RecordingHost host{s};
  // The control panel as the window draws it, the channel list in it.
  HeadlessImGui ui{[this] {
    beginControlPanel(HeadlessImGui::kHeight);
    if (s.hasChannelView() && view().isOpen()) panelChannels(view(), host);
    ImGui::End();
  }};
  static std::unique_ptr<test::TempDir> dir_;
};
std::unique_ptr<test::TempDir> PanelsChannels::dir_;

TEST_F(PanelsChannels, VisibilityCheckboxHidesOnlyThatChannelsPixels) {
  const Image all = nextFrame();
  clickVisible(1);
  EXPECT_TRUE(view().channels()[0].visible);
  EXPECT_FALSE(view().channels()[1].visible);
  EXPECT_TRUE(view().channels()[2].visible);
  EXPECT_EQ(s.settings().channels.visible, std::vector<bool>({true, false, true}));
  EXPECT_EQ(host.error, "");
  const Image withoutSlab = nextFrame();

  // The slab's footprint, from the same checkboxes: every channel off, then
  // the slab alone.
  clickVisible(0);
  clickVisible(2);
  EXPECT_EQ(s.settings().channels.visible, std::vector<bool>({false, false, false}));
  const Image none = nextFrame();
  clickVisible(1);
  const Image slabAlone = nextFrame();
  const std::vector<bool> changed = test::differing(all, withoutSlab, 2);
  const std::vector<bool> slab = test::differing(slabAlone, none, 0);
  int inside = 0, outside = 0;
  for (std::size_t p = 0; p < changed.size(); ++p) {
    if (changed[p]) ++(slab[p] ? inside : outside);
  }
  std::printf("slab's checkbox: %d pixels changed inside its footprint (%d px), %d outside\n",
              inside, count(slab), outside);
  EXPECT_GT(inside, kSize * kSize / 20);
  EXPECT_EQ(outside, 0);

  // Every channel on again: the first frame, to the bit.
  clickVisible(0);
  clickVisible(2);
  EXPECT_EQ(s.settings().channels.visible, std::vector<bool>({true, true, true}));
  EXPECT_EQ(count(test::differing(nextFrame(), all, 0)), 0);
}

TEST_F(PanelsChannels, TypedWindowColourAndModeRenderAsTheCommandLine) {
  const Image defaults = nextFrame();
  // Ctrl+click on the rod's window maximum: its text, typed over.
  ui.click(kPanelTitle, {2, "window", "##max"}, true);
  ui.type("2000");
  ui.clickAway();
  EXPECT_EQ(view().channels()[2].window.min, 100.0);
  EXPECT_EQ(view().channels()[2].window.max, 2000.0);
  // The sphere's swatch opens its picker; green typed into it: yellow.
  ui.click(kPanelTitle, {0, "##colour", "##ColorButton"});
  const std::string picker = HeadlessImGui::popupWindow(kPanelTitle, {0, "##colour", "picker"});
  ASSERT_TRUE(HeadlessImGui::shown(picker));
  ui.click(picker, {"##picker", "##rgb", "##Y"}, true);
  ui.type("255");
  ui.clickAway();
  EXPECT_FALSE(HeadlessImGui::shown(picker));
  EXPECT_EQ(view().channels()[0].color, glm::dvec3(1.0, 1.0, 0.0));
  EXPECT_EQ(host.error, "");
  // The settings the state saves.
  ASSERT_EQ(s.settings().channels.windows.size(), 3u);
  EXPECT_EQ(s.settings().channels.windows[2].max, 2000.0);
  ASSERT_EQ(s.settings().channels.colors.size(), 3u);
  EXPECT_EQ(s.settings().channels.colors[0], glm::dvec3(1.0, 1.0, 0.0));

  const Image edited = nextFrame();
  const Image cli = cliFrame(store(), "ffff00,00ff00,0080ff", "100:3000,50:2500,100:2000");
  const double editedDb = psnr(edited, cli);
  std::printf("typed window and colour: panel's frame vs CLI %.1f dB; vs before %.1f dB\n",
              editedDb, psnr(edited, defaults));
  EXPECT_GE(editedDb, 40.0);
  EXPECT_LT(psnr(edited, defaults), 40.0);  // the edits show

  // The mode's menu: max.
  ui.click(kPanelTitle, {"mode"});
  ui.click("##Combo_00", {1, "max"});
  EXPECT_EQ(view().channels().mode, ChannelMode::Max);
  EXPECT_EQ(s.settings().channels.mode, ChannelMode::Max);
  const Image max = nextFrame();
  const double maxDb = psnr(max, cliFrame(store(), "ffff00,00ff00,0080ff",
                                          "100:3000,50:2500,100:2000", ChannelMode::Max));
  std::printf("mode max: panel's frame vs CLI %.1f dB; vs additive %.1f dB\n", maxDb,
              psnr(max, edited));
  EXPECT_GE(maxDb, 40.0);
  EXPECT_LT(psnr(max, edited), 40.0);
}

TEST_F(PanelsChannels, WindowDraggedWithTheMouseRendersAsTheCommandLine) {
  const Image before = nextFrame();
  // The slab's window is omero's 50..2500, over values 100..2000 (its
  // value 2000 shows at 0.8); the drag moves 3.8 a pixel, from 2000 (the
  // range's top: AlwaysClamp) at its first step. 200 pixels left bring the
  // maximum under 2000, and the slab shows at full strength.
  ui.drag(kPanelTitle, {1, "window", "##max"}, ImVec2(-200.0f, 0.0f));
  const ValueRange w = view().channels()[1].window;
  std::printf("slab's window maximum dragged 200 px left: 2500 -> %.0f\n", w.max);
  EXPECT_LT(w.max, 2000.0 - 100 * 3.8);
  EXPECT_GE(w.max, 2000.0 - 200 * 3.8);
  EXPECT_EQ(w.max, std::round(w.max));  // the panel's format: whole values
  EXPECT_EQ(w.min, 50.0);
  EXPECT_EQ(host.error, "");
  const Image dragged = nextFrame();
  char windows[96];
  std::snprintf(windows, sizeof windows, "100:3000,50:%.0f,100:4000", w.max);
  const double db = psnr(dragged, cliFrame(store(), "ff0000,00ff00,0080ff", windows));
  const int changed = count(test::differing(before, dragged, 2));
  std::printf(
      "dragged window: panel's frame vs CLI --channel-windows %s %.1f dB; %d pixels "
      "changed\n",
      windows, db, changed);
  EXPECT_GE(db, 40.0);
  EXPECT_GT(changed, kSize * kSize / 20);
}

TEST_F(PanelsChannels, ShowOneChannelClosesTheList) {
  ui.click(kPanelTitle, {"Show one channel"});
  EXPECT_FALSE(view().isOpen());
  EXPECT_FALSE(s.settings().channels.enabled);
  EXPECT_EQ(host.error, "");
}

}  // namespace
}  // namespace tessera::desktop
