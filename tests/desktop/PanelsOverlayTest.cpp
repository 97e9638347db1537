// The desktop viewer's overlay panel and drop offer
// (frontends/desktop/PanelsOverlay.cpp), drawn in an ImGui context without
// a window (HeadlessImGui.h) and clicked: a path typed into the panel and
// "Add overlay" open it over the anatomy aligned by world coordinates (the
// crosshair's probe reads the overlay voxel the affines name, the frame
// equals the CPU reference and the frame of Session::openOverlay); the alpha
// slider and "Remove overlay" change the frame as they should; a file
// dropped with no volume open is opened, one dropped over a volume is
// offered, and the offer's buttons add it, replace the volume or do nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "desktop/HeadlessImGui.h"
#include "desktop/PanelFrames.h"
#include "desktop/Panels.h"
#include "desktop/RecordingHost.h"
#include "support/TestSupport.h"
#include "tessera/io/NiftiWriter.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/session/OverlayPanel.h"
#include "tessera/session/Session.h"

namespace tessera::desktop {
namespace {

using test::HeadlessImGui;
constexpr int kSize = test::kPanelFrameSize;
using test::viewFrame;

// The overlay's labels by world position (RAS+ mm): 1 on the right (x > 4),
// 2 on the left (x < -4), within 22 mm of the centre; 0 elsewhere. The
// probes below lie over 2.6 mm (a voxel's diagonal) from every border, so
// that the nearest voxel and the trilinear mix read the label itself.
int labelAt(glm::dvec3 p) {
  if (glm::length(p) >= 22.0 || std::abs(p.x) <= 4.0) return 0;
  return p.x > 0.0 ? 1 : 2;
}

// The anatomy: a ball of radius 20 mm (value 120) on a 48^3 grid of 1 mm
// voxels centred on the origin, axis-aligned.
Volume anatomy() {
  Volume v = Volume::allocate({48, 48, 48}, ScalarType::U8, "ball");
  v.setOrigin(glm::dvec3(-23.5));
  for (int z = 0; z < 48; ++z) {
    for (int y = 0; y < 48; ++y) {
      for (int x = 0; x < 48; ++x) {
        if (glm::length(v.worldOf({x, y, z})) < 20.0) v.setValueAtIndex(v.index(x, y, z), 120.0);
      }
    }
  }
  v.invalidateRange();
  return v;
}

// The overlay: labelAt sampled on another grid, 1.5 mm voxels, 32^3,
// rotated by 30 degrees about z and 15 about x, centred on the origin.
Volume rotatedLabels() {
  const glm::dmat3 r = glm::dmat3(glm::rotate(glm::dmat4(1.0), glm::radians(30.0), {0, 0, 1}) *
                                  glm::rotate(glm::dmat4(1.0), glm::radians(15.0), {1, 0, 0}));
  Volume v = Volume::allocate({32, 32, 32}, ScalarType::U8, "rotated labels");
  v.setSpacing(glm::dvec3(1.5));
  v.setDirection(r);
  v.setOrigin(r * glm::dvec3(-1.5 * 15.5));
  for (int z = 0; z < 32; ++z) {
    for (int y = 0; y < 32; ++y) {
      for (int x = 0; x < 32; ++x)
        v.setValueAtIndex(v.index(x, y, z), labelAt(v.worldOf({x, y, z})));
    }
  }
  v.invalidateRange();
  return v;
}

class PanelsOverlay : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDir>();
    writeNifti(anatomy(), anatomyPath());
    writeNifti(rotatedLabels(), overlayPath());
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static std::string anatomyPath() { return (dir_->path() / "ball.nii.gz").string(); }
  static std::string overlayPath() { return (dir_->path() / "rotated.nii.gz").string(); }

  // The anatomy's look: grey, from an oblique angle.
  static void look(session::Session& session) {
    session.settings().tf = TransferFunction::preset("grey");
    session.settings().camera.azimuthDeg = 60.0;
    session.settings().camera.elevationDeg = 20.0;
  }
  void openAnatomy() {
    look(s);
    s.open(anatomyPath());
  }
  // The crosshair reads, at world positions on both sides and between them,
  // the overlay voxel its own affine names and the label placed there.
  void expectPlacedByWorldCoordinates() {
    ASSERT_NE(s.overlay(), nullptr);
    const Volume& fused = *s.overlay()->fused->volume;
    EXPECT_NE(fused.direction(), glm::dmat3(1.0));
    const glm::dmat4 toIndex = glm::inverse(fused.indexToWorld());
    for (const glm::dvec3 p : {glm::dvec3(10, 0, 0), glm::dvec3(-10, 3, -4), glm::dvec3(0, -12, 5),
                               glm::dvec3(12, 9, 6), glm::dvec3(-7, -11, 9)}) {
      const session::ProbeResult r = s.probe(p);
      const glm::dvec3 expected(toIndex * glm::dvec4(p, 1.0));
      EXPECT_TRUE(r.inOverlay);
      EXPECT_NEAR(glm::length(r.overlayIndex - expected), 0.0, 1e-6)
          << "at (" << p.x << ", " << p.y << ", " << p.z << ") mm";
      // Labels: the nearest voxel's; values: trilinear, of eight equal voxels here.
      EXPECT_NEAR(r.overlayValue, labelAt(p), 1e-9)
          << "at (" << p.x << ", " << p.y << ", " << p.z << ") mm";
    }
  }
  // The same overlay opened straight through the session (what `tessera
  // render --overlay` does), with the options the panel's controls mean.
  static Image directFrame(const session::OverlayControls& controls) {
    return directFrame(&controls);
  }
  // The same without an overlay (null controls).
  static Image directFrame(const session::OverlayControls* controls) {
    session::Session direct("native");
    look(direct);
    direct.open(anatomyPath());
    if (controls) direct.openOverlay(overlayPath(), session::overlayOptionsOf(*controls));
    return direct.render(kSize, kSize);
  }

  // The same view with the volume explored and the overlay opened by the
  // session's own calls (null controls: no overlay).
  static Image directViewFrame(const session::OverlayControls* controls) {
    session::Session direct("native");
    look(direct);
    direct.openInView(anatomyPath());
    if (controls) direct.openOverlay(overlayPath(), session::overlayOptionsOf(*controls));
    return viewFrame(direct);
  }

  session::Session s{"native"};
  test::RecordingHost host{s};
  OverlayUi overlayUi;
  // The control panel with the overlay panel, and the drop offer over the
  // window, as DesktopApp's frame draws them.
  HeadlessImGui ui{[this] {
    beginControlPanel(HeadlessImGui::kHeight);
    if (s.hasVolume()) panelOverlay(s, overlayUi, host);
    ImGui::End();
    if (s.hasVolume()) drawDropOffer(s, overlayUi, host);
  }};
  static std::unique_ptr<test::TempDir> dir_;
};
std::unique_ptr<test::TempDir> PanelsOverlay::dir_;

TEST_F(PanelsOverlay, AddOverlayOpensTheTypedFileAlignedByWorldCoordinates) {
  openAnatomy();
  ui.frame();
  const Image alone = s.render(kSize, kSize);
  ui.click(kPanelTitle, {"labels (atlas)"});
  EXPECT_TRUE(overlayUi.controls.labels);
  EXPECT_EQ(s.overlay(), nullptr);  // nothing open to restyle yet
  ui.click(kPanelTitle, {"##overlaypath"});
  ui.type(overlayPath().c_str());
  ui.click(kPanelTitle, {"Add overlay"});
  EXPECT_EQ(host.error, "");
  ASSERT_NE(s.overlay(), nullptr);
  EXPECT_EQ(s.overlay()->name, overlayPath());
  EXPECT_TRUE(s.overlay()->fused->labels);
  EXPECT_EQ(
      session::overlayPanelLine(*s.overlay()),
      "rotated.nii.gz 32x32x32: " + std::to_string(s.overlay()->labels.labels.size()) + " labels");
  EXPECT_EQ(host.overlayChanges, 1);
  expectPlacedByWorldCoordinates();

  const Image added = s.render(kSize, kSize);
  const double db = psnr(added, s.renderReference(kSize, kSize));
  const int shows = test::differingPixels(alone, added, 2);
  const int direct = test::differingPixels(added, directFrame(overlayUi.controls), 0);
  std::printf(
      "add overlay: %d of %d pixels coloured, GPU vs reference %.2f dB, %d pixels differ "
      "from Session::openOverlay's frame\n",
      shows, kSize * kSize, db, direct);
  EXPECT_GE(db, 40.0);
  EXPECT_GT(shows, kSize * kSize / 20);
  EXPECT_EQ(direct, 0);

  // The alpha slider dragged to its right end: opaque, only where it shows.
  ui.drag(kPanelTitle, {"alpha"}, ImVec2(400.0f, 0.0f));
  EXPECT_EQ(overlayUi.controls.alpha, 1.0f);
  EXPECT_EQ(s.overlay()->options.opacity, 1.0);
  const Image opaque = s.render(kSize, kSize);
  const double opaqueDb = psnr(opaque, s.renderReference(kSize, kSize));
  const int changed = test::differingPixels(added, opaque, 2);
  std::printf("alpha 0.5 -> 1: %d pixels changed, GPU vs reference %.2f dB\n", changed, opaqueDb);
  EXPECT_GE(opaqueDb, 40.0);
  EXPECT_GT(changed, 0);
  EXPECT_LE(changed, shows + kSize * kSize / 100);

  // "Remove overlay": the anatomy's frame, to the bit.
  const int changes = host.overlayChanges;
  ui.click(kPanelTitle, {"Remove overlay"});
  EXPECT_EQ(s.overlay(), nullptr);
  EXPECT_EQ(host.overlayChanges, changes + 1);
  EXPECT_EQ(test::differingPixels(alone, s.render(kSize, kSize), 0), 0);
}

// Another modality's look: the colour map's menu, the window's checkbox
// and its two bounds typed in restyle the open overlay (its file not read
// again), as `--overlay-tf ct-bone --overlay-window 1,2` would open it.
TEST_F(PanelsOverlay, ColourMapAndWindowControlsRestyleTheOverlay) {
  openAnatomy();
  ui.frame();
  ui.click(kPanelTitle, {"##overlaypath"});
  ui.type(overlayPath().c_str());
  ui.click(kPanelTitle, {"Add overlay"});
  ASSERT_NE(s.overlay(), nullptr);
  const std::shared_ptr<const FusedVolume> read = s.overlay()->fused;
  const Image hot = s.render(kSize, kSize);

  ui.click(kPanelTitle, {"colour map"});
  ui.click("##Combo_00", {3, "ct-bone"});
  EXPECT_EQ(overlayUi.controls.colourMap, 3);
  ui.click(kPanelTitle, {"window"});
  ui.click(kPanelTitle, {"##hi"});
  ui.type("2");
  ui.click(kPanelTitle, {"##lo"});
  ui.type("1");
  ui.clickAway();
  EXPECT_EQ(host.error, "");
  ASSERT_NE(s.overlay(), nullptr);
  EXPECT_EQ(s.overlay()->options.tf, "ct-bone");
  ASSERT_TRUE(s.overlay()->options.window.has_value());
  EXPECT_EQ(s.overlay()->options.window->min, 1.0);
  EXPECT_EQ(s.overlay()->options.window->max, 2.0);
  EXPECT_EQ(s.overlay()->fused->volume, read->volume);  // restyled, not read again
  EXPECT_EQ(session::overlayPanelLine(*s.overlay()), "rotated.nii.gz 32x32x32: colour map ct-bone");

  const Image restyled = s.render(kSize, kSize);
  const double db = psnr(restyled, s.renderReference(kSize, kSize));
  const int direct = test::differingPixels(restyled, directFrame(overlayUi.controls), 0);
  std::printf(
      "ct-bone, window 1..2: GPU vs reference %.2f dB, %d pixels changed from hot, %d "
      "differ from Session::openOverlay's frame\n",
      db, test::differingPixels(hot, restyled, 2), direct);
  EXPECT_GE(db, 40.0);
  EXPECT_GT(test::differingPixels(hot, restyled, 2), 0);
  EXPECT_EQ(direct, 0);
}

TEST_F(PanelsOverlay, AFileThatCannotBeReadIsNamedOnTheErrorLine) {
  openAnatomy();
  ui.frame();
  const std::string missing = (dir_->path() / "missing.nii.gz").string();
  ui.click(kPanelTitle, {"##overlaypath"});
  ui.type(missing.c_str());
  ui.click(kPanelTitle, {"Add overlay"});
  std::printf("error line: %s\n", host.error.c_str());
  EXPECT_EQ(s.overlay(), nullptr);
  EXPECT_NE(host.error.find(missing), std::string::npos) << host.error;
  EXPECT_EQ(host.overlayChanges, 0);
}

TEST_F(PanelsOverlay, AFileDroppedWithNoVolumeOpenIsOpened) {
  offerDrop(s, overlayUi, host, anatomyPath());
  EXPECT_EQ(host.opened, std::vector<std::string>({anatomyPath()}));
  EXPECT_TRUE(overlayUi.dropped.empty());
  EXPECT_EQ(s.name(), anatomyPath());
  ui.frame();
  EXPECT_FALSE(HeadlessImGui::shown(kDropOfferTitle));
}

TEST_F(PanelsOverlay, ASecondFileDroppedIsOfferedAndAddedAsTheOverlay) {
  openAnatomy();
  ui.frame();
  offerDrop(s, overlayUi, host, overlayPath());
  EXPECT_TRUE(host.opened.empty());
  EXPECT_EQ(overlayUi.dropped, overlayPath());
  ui.frame();
  ASSERT_TRUE(HeadlessImGui::shown(kDropOfferTitle));
  ui.click(kDropOfferTitle, {"Add as overlay"});
  ui.frame();
  EXPECT_FALSE(HeadlessImGui::shown(kDropOfferTitle));
  EXPECT_TRUE(overlayUi.dropped.empty());
  EXPECT_EQ(std::string(overlayUi.path), overlayPath());  // the panel's path shows it
  EXPECT_EQ(host.error, "");
  ASSERT_NE(s.overlay(), nullptr);
  EXPECT_EQ(s.overlay()->name, overlayPath());
  EXPECT_FALSE(s.overlay()->fused->labels);  // the panel's controls: colour map hot
  EXPECT_EQ(s.overlay()->options.tf, "hot");
  expectPlacedByWorldCoordinates();
  const Image fused = s.render(kSize, kSize);
  const double db = psnr(fused, s.renderReference(kSize, kSize));
  const int direct = test::differingPixels(fused, directFrame(overlayUi.controls), 0);
  std::printf(
      "dropped and added: GPU vs reference %.2f dB, %d pixels differ from "
      "Session::openOverlay's frame\n",
      db, direct);
  EXPECT_GE(db, 40.0);
  EXPECT_EQ(direct, 0);
}

// The desktop's own path: the anatomy dropped on the empty window is opened
// as its file panel opens one (explored in the view), the overlay dropped
// next is offered and added; the 3D view's frame shows it, equal to the
// view of a session that made the same calls itself, and "Remove overlay"
// gives the view's frame back to the bit.
TEST_F(PanelsOverlay, FilesDroppedInTurnShowTheSecondOverTheFirstInTheView) {
  look(s);
  offerDrop(s, overlayUi, host, anatomyPath());
  ASSERT_EQ(host.opened, std::vector<std::string>({anatomyPath()}));
  EXPECT_TRUE(s.exploring());
  ui.frame();
  const Image alone = viewFrame(s);
  offerDrop(s, overlayUi, host, overlayPath());
  ui.frame();
  ui.click(kDropOfferTitle, {"Add as overlay"});
  EXPECT_EQ(host.error, "");
  expectPlacedByWorldCoordinates();
  const Image fused = viewFrame(s);
  const int shows = test::differingPixels(alone, fused, 2);
  const int aloneOff = test::differingPixels(alone, directViewFrame(nullptr), 0);
  const int fusedOff = test::differingPixels(fused, directViewFrame(&overlayUi.controls), 0);
  std::printf(
      "dropped in turn: %d of %d pixels of the view coloured; %d / %d pixels differ from "
      "the view of the session's own calls (alone / with the overlay)\n",
      shows, kSize * kSize, aloneOff, fusedOff);
  EXPECT_GT(shows, kSize * kSize / 20);
  EXPECT_EQ(aloneOff, 0);
  EXPECT_EQ(fusedOff, 0);
  ui.click(kPanelTitle, {"Remove overlay"});
  EXPECT_EQ(s.overlay(), nullptr);
  EXPECT_EQ(test::differingPixels(alone, viewFrame(s), 0), 0);
}

TEST_F(PanelsOverlay, TheOffersReplaceOpensTheFileAndCancelKeepsTheVolume) {
  openAnatomy();
  ui.frame();
  offerDrop(s, overlayUi, host, overlayPath());
  ui.frame();
  ui.click(kDropOfferTitle, {"Cancel"});
  ui.frame();
  EXPECT_FALSE(HeadlessImGui::shown(kDropOfferTitle));
  EXPECT_TRUE(overlayUi.dropped.empty());
  EXPECT_TRUE(host.opened.empty());
  EXPECT_EQ(s.overlay(), nullptr);
  EXPECT_EQ(s.name(), anatomyPath());

  offerDrop(s, overlayUi, host, overlayPath());
  ui.frame();
  ui.click(kDropOfferTitle, {"Replace"});
  ui.frame();
  EXPECT_FALSE(HeadlessImGui::shown(kDropOfferTitle));
  EXPECT_EQ(host.opened, std::vector<std::string>({overlayPath()}));
  EXPECT_EQ(s.overlay(), nullptr);
  EXPECT_EQ(s.name(), overlayPath());
}

}  // namespace
}  // namespace tessera::desktop
