// Files dropped on the desktop viewer's window, from the drop callback on:
// GLFW's callback (gpu::GlfwWindow::onDrop) hands the paths to
// desktop::filesDropped, which DesktopApp registers as its handler, and the
// next frame's desktop::handleDrops (DesktopApp's runFrame, after the
// window's events) opens or offers them. GLFW itself needs a display, so the
// test calls filesDropped with the path lists a drop gives and runs the
// frames headless (HeadlessImGui.h): one file opens, two open the first and
// offer the second as its overlay, a folder of DICOM files opens as its
// series, a path that cannot be read is named on the error line.
// tests/glfw/GlfwDropTest.cpp drops files on a real GlfwWindow under Xvfb
// and checks the path lists the window hands over.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "desktop/HeadlessImGui.h"
#include "desktop/PanelFrames.h"
#include "desktop/Panels.h"
#include "desktop/RecordingHost.h"
#include "support/TestSupport.h"
#include "tessera/io/DicomSeriesReader.h"
#include "tessera/io/NiftiWriter.h"
#include "tessera/io/Procedural.h"
#include "tessera/session/Session.h"

namespace tessera::desktop {
namespace {

using test::HeadlessImGui;
namespace fs = std::filesystem;

// 40x36x12 u16, every voxel its own index, 0.8 x 0.8 x 2.5 mm: a CT series.
Volume rampVolume() {
  Volume v = Volume::allocate({40, 36, 12}, ScalarType::U16, "ramp");
  v.setSpacing({0.8, 0.8, 2.5});
  for (std::size_t i = 0; i < v.voxelCount(); ++i) v.setValueAtIndex(i, double(i % 4000));
  v.invalidateRange();
  return v;
}

class PanelsDrop : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDir>();
    writeNifti(makeProcedural("gen:sphere:32"), dir_->path() / "anatomy.nii.gz");
    writeNifti(makeProcedural("gen:shepp-logan:32"), dir_->path() / "overlay.nii.gz");
    writeNifti(makeProcedural("gen:sphere:16"), dir_->path() / "third.nii.gz");
    DicomWriteOptions o;
    o.modality = "CT";
    writeDicomSeries(rampVolume(), dir_->path() / "ct-series", o);
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static std::string path(const char* name) { return (dir_->path() / name).string(); }

  // What the window's drop callback does with the paths GLFW hands it, then
  // the next frame.
  void drop(const std::vector<std::string>& paths) {
    filesDropped(overlayUi, paths);  // DesktopApp's onDrop handler
    ui.frame();
  }

  session::Session s{"native"};
  test::RecordingHost host{s};
  OverlayUi overlayUi;
  // DesktopApp's frame: the drops after the events, the panel, the offer.
  HeadlessImGui ui{[this] {
    handleDrops(s, overlayUi, host);
    beginControlPanel(HeadlessImGui::kHeight);
    if (s.hasVolume()) panelOverlay(s, overlayUi, host);
    ImGui::End();
    if (s.hasVolume()) drawDropOffer(s, overlayUi, host);
  }};
  static std::unique_ptr<test::TempDir> dir_;
};
std::unique_ptr<test::TempDir> PanelsDrop::dir_;

TEST_F(PanelsDrop, OneFileOnTheEmptyWindowIsOpened) {
  drop({path("anatomy.nii.gz")});
  EXPECT_EQ(host.opened, std::vector<std::string>({path("anatomy.nii.gz")}));
  EXPECT_EQ(host.error, "");
  EXPECT_EQ(s.name(), path("anatomy.nii.gz"));
  EXPECT_TRUE(s.exploring());
  EXPECT_TRUE(overlayUi.pendingDrops.empty());
  EXPECT_FALSE(HeadlessImGui::shown(kDropOfferTitle));
}

TEST_F(PanelsDrop, OneFileOverAnOpenVolumeIsOfferedNotOpened) {
  drop({path("anatomy.nii.gz")});
  drop({path("overlay.nii.gz")});
  EXPECT_EQ(host.opened.size(), 1u);
  EXPECT_EQ(s.name(), path("anatomy.nii.gz"));
  ui.frame();
  EXPECT_TRUE(HeadlessImGui::shown(kDropOfferTitle));
  EXPECT_EQ(overlayUi.dropped, path("overlay.nii.gz"));
}

TEST_F(PanelsDrop, TwoFilesOpenTheFirstAndOfferTheSecondAsItsOverlay) {
  drop({path("anatomy.nii.gz"), path("overlay.nii.gz")});
  EXPECT_EQ(host.opened, std::vector<std::string>({path("anatomy.nii.gz")}));
  EXPECT_EQ(host.error, "");
  EXPECT_EQ(s.name(), path("anatomy.nii.gz"));
  ui.frame();
  ASSERT_TRUE(HeadlessImGui::shown(kDropOfferTitle));
  ui.click(kDropOfferTitle, {"Add as overlay"});
  EXPECT_EQ(host.error, "");
  ASSERT_NE(s.overlay(), nullptr);
  EXPECT_EQ(s.overlay()->name, path("overlay.nii.gz"));
  EXPECT_EQ(host.overlayChanges, 1);
  // The overlay the drop added equals the one `--overlay` opens.
  session::Session cli("native");
  cli.openInView(path("anatomy.nii.gz"));
  cli.openOverlay(path("overlay.nii.gz"), session::overlayOptionsOf(overlayUi.controls));
  const int off = test::differingPixels(test::viewFrame(s), test::viewFrame(cli));
  std::printf("two files dropped: %d pixels differ from the view with --overlay\n", off);
  EXPECT_EQ(off, 0);
}

TEST_F(PanelsDrop, MoreThanTwoFilesNameTheRestAsNotOpened) {
  drop({path("anatomy.nii.gz"), path("overlay.nii.gz"), path("third.nii.gz")});
  EXPECT_EQ(s.name(), path("anatomy.nii.gz"));
  EXPECT_EQ(overlayUi.dropped, path("overlay.nii.gz"));
  std::printf("error line: %s\n", host.error.c_str());
  EXPECT_EQ(host.error,
            "3 files dropped: the first is opened and the second offered as its overlay; "
            "third.nii.gz not opened");
}

TEST_F(PanelsDrop, AFolderOfDicomFilesOpensAsItsSeries) {
  const std::string folder = path("ct-series");
  drop({folder});
  EXPECT_EQ(host.error, "");
  EXPECT_EQ(s.name(), folder);
  const Volume& shown = s.view().volume();  // the overview: the series itself, small as it is
  const Volume read = readDicomSeries(folder);
  const std::size_t off = test::differingVoxels(shown, read);
  std::printf("DICOM folder dropped: %dx%dx%d voxels, %zu differ from the series read alone\n",
              shown.dims().x, shown.dims().y, shown.dims().z, off);
  EXPECT_EQ(shown.dims(), glm::ivec3(40, 36, 12));
  EXPECT_EQ(off, 0u);
  EXPECT_NEAR(shown.spacing().z, 2.5, 1e-6);
}

TEST_F(PanelsDrop, APathThatCannotBeReadIsNamedOnTheErrorLine) {
  const std::string bad = path("no-such-file.nii.gz");
  drop({bad});
  std::printf("error line: %s\n", host.error.c_str());
  EXPECT_FALSE(s.hasVolume());
  EXPECT_NE(host.error.find(bad), std::string::npos) << host.error;
  EXPECT_NE(host.error.find("(the previous volume stays)"), std::string::npos);
  // The first of two unreadable: named, and the second is not offered.
  drop({bad, path("overlay.nii.gz")});
  EXPECT_NE(host.error.find(bad), std::string::npos) << host.error;
  EXPECT_TRUE(overlayUi.dropped.empty());
  ui.frame();
  EXPECT_FALSE(HeadlessImGui::shown(kDropOfferTitle));
  // Over an open volume, offered, and its "Add as overlay" names it.
  drop({path("anatomy.nii.gz")});
  drop({bad});
  ui.frame();
  ui.click(kDropOfferTitle, {"Add as overlay"});
  EXPECT_NE(host.error.find(bad), std::string::npos) << host.error;
  EXPECT_EQ(s.overlay(), nullptr);
  EXPECT_EQ(s.name(), path("anatomy.nii.gz"));
}

}  // namespace
}  // namespace tessera::desktop
