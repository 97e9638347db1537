// The desktop viewer's exploring panel (frontends/desktop/PanelsExplore.cpp),
// drawn in an ImGui context without a window (HeadlessImGui.h) and clicked:
// the region's side typed in and "View region (V)" show the box around the
// crosshair, voxel for voxel what `tessera render FILE --region BOX` reads
// and placed where it lies; "Grid view (G)" and a grid move's button show
// the grid's blocks, each `--region BLOCK`'s voxels; "Overview (O)" shows the
// whole volume again.
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
#include "tessera/session/Session.h"

namespace tessera::desktop {
namespace {

using test::HeadlessImGui;

// 64^3 f32 whose every voxel holds its own index (x + 100 y + 10000 z), so
// that a box's voxels name where they came from; 1.5 mm voxels, off the
// origin.
Volume indexVolume() {
  Volume v = Volume::allocate({64, 64, 64}, ScalarType::F32, "index");
  v.setSpacing(glm::dvec3(1.5));
  v.setOrigin(glm::dvec3(-40.0, 12.0, 7.0));
  for (int z = 0; z < 64; ++z) {
    for (int y = 0; y < 64; ++y) {
      for (int x = 0; x < 64; ++x) v.setValueAtIndex(v.index(x, y, z), x + 100.0 * y + 1e4 * z);
    }
  }
  v.invalidateRange();
  return v;
}

class PanelsExplore : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDir>();
    writeNifti(indexVolume(), dir_->path() / "index.nii.gz");
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static std::string file() { return (dir_->path() / "index.nii.gz").string(); }

  void SetUp() override {
    host.openFile(file());
    ASSERT_EQ(host.error, "");
    ASSERT_TRUE(s.exploring());
    ui.frame();
  }
  // What `tessera render FILE --region BOX` reads (a fresh session).
  static Volume regionRead(const lod::VoxelBox& box) {
    session::Session cli("native");
    session::OpenOptions open;
    open.region = session::boxText(box);
    cli.open(file(), open);
    return cli.volume();
  }
  // The 3D view shows `box`: its voxels are `--region BOX`'s, at its place.
  void expectShowsRegion(const lod::VoxelBox& box, const char* what) {
    const Volume& shown = s.view().volume();
    const Volume read = regionRead(box);
    const std::size_t off = test::differingVoxels(shown, read);
    const glm::dvec3 at(shown.indexToWorld() * glm::dvec4(0.0, 0.0, 0.0, 1.0));
    const glm::dvec3 expected(read.indexToWorld() * glm::dvec4(0.0, 0.0, 0.0, 1.0));
    std::printf(
        "%s %s: %dx%dx%d voxels, %zu differ from render --region's; first voxel at "
        "(%.2f, %.2f, %.2f) mm, %.2g mm from render --region's\n",
        what, session::boxText(box).c_str(), shown.dims().x, shown.dims().y, shown.dims().z, off,
        at.x, at.y, at.z, glm::length(at - expected));
    EXPECT_EQ(off, 0u);
    EXPECT_NEAR(glm::length(at - expected), 0.0, 1e-9);
    EXPECT_EQ(shown.valueAt(0, 0, 0), box.begin.x + 100.0 * box.begin.y + 1e4 * box.begin.z);
  }

  session::Session s{"native"};
  test::RecordingHost host{s};
  ExploreUi exploreUi;
  HeadlessImGui ui{[this] {
    beginControlPanel(HeadlessImGui::kHeight);
    panelExplore(s, exploreUi, host);
    ImGui::End();
  }};
  static std::unique_ptr<test::TempDir> dir_;
};
std::unique_ptr<test::TempDir> PanelsExplore::dir_;

TEST_F(PanelsExplore, ViewRegionShowsTheBoxRenderRegionReads) {
  session::Exploration& e = s.exploration();
  e.explorer().setCrosshair({20, 30, 40});  // a click in a slice view
  ui.click(kPanelTitle, {"region side"}, true);
  ui.type("24");
  ui.clickAway();
  EXPECT_EQ(e.explorer().regionSide(), 24);
  const int changes = host.viewChanges;
  ui.click(kPanelTitle, {"View region (V)"});
  EXPECT_EQ(host.error, "");
  EXPECT_EQ(e.mode(), session::ExploreMode::Region);
  ASSERT_TRUE(e.shown().has_value());
  const lod::VoxelBox box = *e.shown();
  EXPECT_EQ(box.size(), glm::ivec3(24));
  EXPECT_TRUE(glm::all(glm::lessThanEqual(box.begin, glm::ivec3(20, 30, 40))));
  EXPECT_TRUE(glm::all(glm::greaterThan(box.end, glm::ivec3(20, 30, 40))));
  expectShowsRegion(box, "View region");
  EXPECT_EQ(host.viewChanges, changes + 1);

  ui.click(kPanelTitle, {"Overview (O)"});
  EXPECT_EQ(e.mode(), session::ExploreMode::Overview);
  EXPECT_EQ(test::differingVoxels(s.view().volume(), indexVolume()), 0u);
}

TEST_F(PanelsExplore, GridViewAndItsMovesShowTheBlocksRenderRegionReads) {
  session::Exploration& e = s.exploration();
  // Cells of 16 voxels (a 2x2x2 block: 32^3), the crosshair near the
  // centre: every move stays whole on the grid.
  e.setGrid(lod::GridNavigator(e.dims(), glm::ivec3(16)));
  e.explorer().setCrosshair({31, 33, 29});
  ui.click(kPanelTitle, {"Grid view (G)"});
  EXPECT_EQ(host.error, "");
  ASSERT_EQ(e.mode(), session::ExploreMode::Grid);
  ASSERT_TRUE(e.gridBlock().has_value());
  const lod::VoxelBox first = *e.gridBlock();
  EXPECT_EQ(first.size(), glm::ivec3(32));
  expectShowsRegion(first, "Grid view");
  ui.frame();  // the moves' buttons appear in grid mode

  // The first move the grid allows from here, by its button.
  const lod::GridNavigator& grid = e.explorer().grid();
  const lod::ViewMove moves[6] = {lod::ViewMove::Forward, lod::ViewMove::Back, lod::ViewMove::Left,
                                  lod::ViewMove::Right,   lod::ViewMove::Up,   lod::ViewMove::Down};
  std::string label;
  for (const lod::ViewMove m : moves) {
    const lod::GridMove g = lod::viewMoveToGridMove(s.view().camera().basis(), m);
    if (grid.check(grid.point(), g).moved) {
      label = std::string(lod::viewMoveName(m)) + " " + g.name();
      break;
    }
  }
  ASSERT_FALSE(label.empty()) << "no move allowed on the grid";
  ui.click(kPanelTitle, {label.c_str()});
  EXPECT_EQ(host.error, "");
  ASSERT_TRUE(e.gridBlock().has_value());
  const lod::VoxelBox moved = *e.gridBlock();
  EXPECT_EQ(moved.size(), glm::ivec3(32));
  EXPECT_EQ(glm::length(glm::dvec3(moved.begin - first.begin)), 16.0);  // one cell
  std::printf("grid move '%s': block %s -> %s\n", label.c_str(), session::boxText(first).c_str(),
              session::boxText(moved).c_str());
  expectShowsRegion(moved, "Grid move");
}

}  // namespace
}  // namespace tessera::desktop
