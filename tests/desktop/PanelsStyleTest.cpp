// The desktop viewer's look panels (frontends/desktop/PanelsStyle.cpp),
// drawn in an ImGui context without a window (HeadlessImGui.h) and clicked:
// a preset chosen from the TF's menu, a window and level typed in, the
// technique's menu and the mode's give the frame of the command line with
// the same flags (`tessera render FILE --tf ct-bone --window 40,160
// --technique slice3d --mode mip`), to the bit: the session's look as the
// panels left it (what Save state writes) rendered by `render --state`, and
// the 3D view's frame against the view of a session given those settings;
// and so do shading's checkbox, the crop box's range and the label volume's
// checkbox (`--shade --crop ... --labels`).
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>

#include "desktop/HeadlessImGui.h"
#include "desktop/PanelFrames.h"
#include "desktop/Panels.h"
#include "desktop/RecordingHost.h"
#include "support/TestSupport.h"
#include "tessera/io/NiftiWriter.h"
#include "tessera/io/Procedural.h"
#include "tessera/render/LabelTable.h"
#include "tessera/session/Session.h"

namespace tessera::desktop {
namespace {

using test::HeadlessImGui;
constexpr int kSize = test::kPanelFrameSize;

// The camera the user turned the view to (--azimuth 40 --elevation 25).
void look(session::Settings& s) {
  s.camera.azimuthDeg = 40.0;
  s.camera.elevationDeg = 25.0;
}
void turn(viewer::Viewer& v) {
  v.camera().azimuthDeg = 40.0;
  v.camera().elevationDeg = 25.0;
}

// The flags' settings (`--tf TF --window LO,HI --technique T --mode M`).
struct Flags {
  std::string tf = "mr-default";
  std::optional<ValueRange> window;
  std::string technique = "raycast";
  RenderMode mode = RenderMode::Composite;
  bool shade = false;     // --shade
  double cropMaxZ = 1.0;  // --crop 0:1,0:1,0:Z
  bool labels = false;    // --labels
  void applyTo(session::Settings& s) const {
    look(s);
    s.tf = TransferFunction::preset(tf);
    s.tfIsDefault = false;
    s.window = window;
    s.technique = technique;
    s.render.mode = mode;
    s.render.shading.enabled = shade;
    s.render.clipping.cropMax.z = cropMaxZ;
    s.labels = labels;
    if (labels) render::applyLabelSettings(s.render);  // as RenderCommand.cpp does
  }
};

class PanelsStyle : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDir>();
    writeNifti(makeProcedural("gen:shepp-logan:48"), dir_->path() / "phantom.nii.gz");
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static std::string file() { return (dir_->path() / "phantom.nii.gz").string(); }

  void SetUp() override {
    host.openFile(file());
    ASSERT_EQ(host.error, "");
    turn(s.view());
    ui.frame();
  }
  // `tessera render FILE` with the flags: a fresh session.
  static Image renderFrame(const Flags& flags) {
    session::Session cli("native");
    flags.applyTo(cli.settings());
    cli.open(file());
    return cli.render(kSize, kSize);
  }
  // The 3D view of a session that opened the file and was given the
  // flags' settings (Session::setSettings: what a state with them restores).
  static Image flagsViewFrame(const Flags& flags) {
    session::Session cli("native");
    cli.openInView(file());
    session::Settings settings = cli.currentSettings();
    flags.applyTo(settings);
    cli.setSettings(settings);
    return test::viewFrame(cli);
  }
  // Both comparisons: the panel session's view and its look rendered.
  void expectFlagsFrame(const Flags& flags, const char* what) {
    const Image view = test::viewFrame(s);
    const Image flagsView = flagsViewFrame(flags);
    const Image rendered = renderFrame(flags);
    EXPECT_GT(test::differingPixels(rendered, renderFrame(Flags{}), 2), 0);
    const int viewOff = test::differingPixels(view, flagsView);
    // The look as Save state writes it, given to a fresh session that opens
    // the file (`render FILE --state STATE`).
    session::Session again("native");
    again.setSettings(s.currentSettings());
    again.open(file());
    const int lookOff = test::differingPixels(again.render(kSize, kSize), rendered);
    std::printf(
        "%s: %d pixels differ between the panel's look rendered and `render`'s frame, %d "
        "between the 3D view and the view of a session given the flags\n",
        what, lookOff, viewOff);
    EXPECT_EQ(viewOff, 0);
    EXPECT_EQ(lookOff, 0);
  }
  void typeInto(const char* label, const char* text) { ui.typeInto(kPanelTitle, label, text); }

  session::Session s{"native"};
  test::RecordingHost host{s};
  StyleUi styleUi;
  // The panels below Rendering in the window (Shading, Clipping, Labels),
  // drawn alone: the control panel is taller than the window.
  bool lower = false;
  // The look's panels in the control panel, as DesktopApp draws them.
  HeadlessImGui ui{[this] {
    beginControlPanel(HeadlessImGui::kHeight);
    if (s.hasVolume() && !lower) {
      panelTransferFunction(s, styleUi, host);
      panelWindowLevel(s.view());
      panelRendering(s.view(), host);
    } else if (s.hasVolume()) {
      panelShading(s.view());
      panelClipping(s.view(), styleUi);
      panelLabels(s.view(), styleUi, host);
    }
    ImGui::End();
  }};
  static std::unique_ptr<test::TempDir> dir_;
};
std::unique_ptr<test::TempDir> PanelsStyle::dir_;

TEST_F(PanelsStyle, PresetWindowTechniqueAndModeGiveTheCommandLinesFrame) {
  Flags flags;
  const Image before = test::viewFrame(s);

  ui.click(kPanelTitle, {"preset"});
  ui.click("##Combo_00", {"ct-bone"});
  EXPECT_EQ(s.view().tfEditor().transferFunction().name, "ct-bone");
  flags.tf = "ct-bone";
  EXPECT_GT(test::differingPixels(before, test::viewFrame(s), 2), kSize * kSize / 50);
  expectFlagsFrame(flags, "--tf ct-bone");

  typeInto("window", "120");
  typeInto("level", "100");
  EXPECT_EQ(s.view().window().min, 40.0);
  EXPECT_EQ(s.view().window().max, 160.0);
  flags.window = ValueRange{40.0, 160.0};
  expectFlagsFrame(flags, "--tf ct-bone --window 40,160");

  ui.click(kPanelTitle, {"technique"});
  ui.click("##Combo_00", {"slice3d"});
  EXPECT_EQ(host.error, "");
  EXPECT_EQ(s.view().technique(), "slice3d");
  flags.technique = "slice3d";
  expectFlagsFrame(flags, "... --technique slice3d");

  ui.click(kPanelTitle, {"mode"});
  ui.click("##Combo_00", {1, "MIP"});
  EXPECT_EQ(s.view().settings().mode, RenderMode::Mip);
  flags.mode = RenderMode::Mip;
  expectFlagsFrame(flags, "... --mode mip");
}

// Shading's checkbox, the crop box's z range typed in and the label
// volume's checkbox, each step: `render --shade`, `--crop 0:1,0:1,0:0.6`,
// `--labels`'s frame.
TEST_F(PanelsStyle, ShadingCropAndLabelsGiveTheCommandLinesFrame) {
  Flags flags;
  lower = true;
  ui.frame();
  ui.click(kPanelTitle, {"shade (gradient lighting)"});
  EXPECT_TRUE(s.view().settings().shading.enabled);
  flags.shade = true;
  expectFlagsFrame(flags, "--shade");

  ui.click(kPanelTitle, {"crop z", 1, ""}, true);  // the range's upper end, typed
  ui.type("0.6");
  ui.clickAway();
  EXPECT_FLOAT_EQ(static_cast<float>(s.view().settings().clipping.cropMax.z), 0.6f);
  EXPECT_EQ(s.view().settings().clipping.cropMin, glm::dvec3(0.0));
  flags.cropMaxZ = s.view().settings().clipping.cropMax.z;  // 0.6 as a float holds it
  expectFlagsFrame(flags, "--shade --crop 0:1,0:1,0:0.6");

  ui.click(kPanelTitle, {"label volume (atlas)"});
  EXPECT_EQ(host.error, "");
  EXPECT_TRUE(s.view().labelsOn());
  flags.labels = true;
  expectFlagsFrame(flags, "--shade --crop 0:1,0:1,0:0.6 --labels");
}

}  // namespace
}  // namespace tessera::desktop
