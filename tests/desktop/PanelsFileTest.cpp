// The desktop viewer's file panel (frontends/desktop/PanelsFile.cpp), drawn
// in an ImGui context without a window (HeadlessImGui.h) and clicked: a path
// typed in and "Open" explore that file in the view (the frame of a session
// that opened it itself) and put it first in the recent list; a file that
// cannot be read is named on the error line with the reader's own message,
// the volume shown stays (the line lasting over the frames after it) and a
// file that is gone leaves the recent list; an
// entry of the "recent" menu opens that volume again; "Save state" and
// "Load" give the saved view back.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "desktop/HeadlessImGui.h"
#include "desktop/PanelFrames.h"
#include "desktop/Panels.h"
#include "desktop/RecordingHost.h"
#include "support/TestSupport.h"
#include "tessera/io/NiftiWriter.h"
#include "tessera/io/Procedural.h"
#include "tessera/session/Session.h"

namespace tessera::desktop {
namespace {

using test::HeadlessImGui;
namespace fs = std::filesystem;

class PanelsFile : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDir>();
    writeNifti(makeProcedural("gen:sphere:40"), dir_->path() / "sphere.nii.gz");
    writeNifti(makeProcedural("gen:shepp-logan:40"), dir_->path() / "phantom.nii.gz");
    // A NIfTI name over bytes that are not one.
    std::ofstream(dir_->path() / "corrupt.nii", std::ios::binary) << "not a NIfTI header at all";
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static std::string path(const char* name) { return (dir_->path() / name).string(); }
  // The message a session's own open gives for `spec`.
  static std::string openError(const std::string& spec) {
    session::Session other("native");
    try {
      other.openInView(spec);
    } catch (const Error& e) {
      return e.what();
    }
    ADD_FAILURE() << spec << " opened";
    return "";
  }

  void open(const std::string& file) {
    ui.click(kPanelTitle, {"##path"});
    ui.type(file.c_str());
    ui.click(kPanelTitle, {"Open"});
  }

  test::TempDir home;  // the recent list's file is written here
  session::Session s{"native"};
  test::RecordingHost host{s, home.path() / "recent-files.json"};
  ExploreUi exploreUi;
  // The file panel and, below it as in the window, the exploring panel
  // (which runs every frame: the zoom swap's upkeep).
  HeadlessImGui ui{[this] {
    beginControlPanel(HeadlessImGui::kHeight);
    panelFile(s, host.files, host);
    panelExplore(s, exploreUi, host);
    ImGui::End();
  }};
  static std::unique_ptr<test::TempDir> dir_;
};
std::unique_ptr<test::TempDir> PanelsFile::dir_;

TEST_F(PanelsFile, OpenExploresTheTypedFileAndPutsItFirstInTheRecentList) {
  open(path("sphere.nii.gz"));
  EXPECT_EQ(host.error, "");
  EXPECT_EQ(s.name(), path("sphere.nii.gz"));
  EXPECT_TRUE(s.exploring());
  EXPECT_EQ(host.viewChanges, 1);
  ASSERT_FALSE(host.files.recent.entries().empty());
  EXPECT_EQ(host.files.recent.entries()[0], fs::absolute(path("sphere.nii.gz")).string());
  // Written to the file, for the next session.
  viewer::RecentFiles next(home.path() / "recent-files.json");
  next.load();
  EXPECT_EQ(next.entries(), host.files.recent.entries());
  session::Session direct("native");
  direct.openInView(path("sphere.nii.gz"));
  const int off = test::differingPixels(test::viewFrame(s), test::viewFrame(direct));
  std::printf("Open: %d pixels differ from the view of a session that opened it itself\n", off);
  EXPECT_EQ(off, 0);
}

TEST_F(PanelsFile, AFileThatCannotBeReadIsNamedOnTheErrorLineAndThePreviousVolumeStays) {
  host.openFile(path("sphere.nii.gz"));
  ASSERT_EQ(host.error, "");
  const std::string missing = path("gone.nii.gz");
  host.files.recent.add(missing);  // opened once, deleted since
  for (const std::string& bad : {missing, path("corrupt.nii")}) {
    host.files.path[0] = '\0';  // the field emptied, as the user deletes its text
    open(bad);
    std::printf("error line: %s\n", host.error.c_str());
    EXPECT_EQ(host.error, openError(bad) + " (the previous volume stays)");
    EXPECT_NE(host.error.find(fs::path(bad).filename().string()), std::string::npos);
    EXPECT_EQ(s.name(), path("sphere.nii.gz"));
    EXPECT_EQ(s.view().volume().dims(), glm::ivec3(40));
    const std::string line = host.error;
    for (int i = 0; i < 3; ++i) ui.frame();
    EXPECT_EQ(host.error, line) << "the error line lasts until the next action";
  }
  const auto& entries = host.files.recent.entries();
  EXPECT_EQ(std::find(entries.begin(), entries.end(), missing), entries.end());
  EXPECT_EQ(host.viewChanges, 1);  // only the first open changed the view
}

TEST_F(PanelsFile, ARecentEntryOpensThatVolumeAgain) {
  host.openFile(path("sphere.nii.gz"));
  host.openFile(path("phantom.nii.gz"));
  const std::string sphere = fs::absolute(path("sphere.nii.gz")).string();
  ASSERT_EQ(host.files.recent.entries().size(), 2u);
  EXPECT_EQ(host.files.recent.entries()[1], sphere);
  ui.frame();
  ui.click(kPanelTitle, {"recent"});
  const std::string item = "2  sphere.nii.gz##" + sphere;
  ui.click("##Combo_00", {item.c_str()});
  EXPECT_EQ(host.error, "");
  EXPECT_EQ(s.name(), sphere);
  EXPECT_EQ(host.files.recent.entries()[0], sphere);
}

TEST_F(PanelsFile, SaveStateAndLoadGiveTheSavedViewBack) {
  host.openFile(path("phantom.nii.gz"));
  s.view().camera().azimuthDeg = 35.0;
  s.choosePreset("ct-bone");
  const Image saved = test::viewFrame(s);
  const std::string state = (home.path() / "state.json").string();
  host.files.statePath[0] = '\0';  // the default name deleted, another typed in
  ui.click(kPanelTitle, {"##state"});
  ui.type(state.c_str());
  ui.click(kPanelTitle, {"Save state"});
  EXPECT_EQ(host.error, "");
  ASSERT_TRUE(fs::exists(state));
  s.view().camera().azimuthDeg = 120.0;
  s.choosePreset("grey");
  const Image changed = test::viewFrame(s);
  ui.click(kPanelTitle, {"Load"});
  EXPECT_EQ(host.error, "");
  EXPECT_EQ(host.statesLoaded, 1);
  const int off = test::differingPixels(test::viewFrame(s), saved);
  std::printf("Load: %d pixels differ from the saved view (%d changed before it)\n", off,
              test::differingPixels(changed, saved));
  EXPECT_GT(test::differingPixels(changed, saved), 0);
  EXPECT_EQ(off, 0);
}

}  // namespace
}  // namespace tessera::desktop
