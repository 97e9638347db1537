// The overlay in the session's state (session/Fusion.h overlayState,
// Session::state / restore / saveState / loadState): saved with its file and
// look, restored into another session (the probe names the same region),
// restyled without reading the file again, kept by a state without one;
// bad values named.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "support/MricronAtlas.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/core/SliceImage.h"
#include "tessera/reference/FusedVolume.h"
#include "tessera/session/Session.h"

namespace tessera::session {
namespace {

using test::haveMricron;
using test::kAal;
using test::kAalNames;
using test::kCh2;

void openCh2(Session& s) {
  OpenOptions open;
  open.hostVoxels = true;
  s.open(kCh2, open);
}

std::string messageOf(Session& s, const nlohmann::json& state) {
  try {
    s.restore(state);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(FusionState, LabelOverlayRoundTripsThroughAStateFile) {
  if (!haveMricron()) GTEST_SKIP() << "mricron templates not installed";
  test::TempDir dir;
  const auto path = (dir / "state.json").string();
  {
    Session s("native");
    openCh2(s);
    OverlayOptions o;
    o.labels = true;
    o.labelTable = kAalNames;
    o.opacity = 0.6;
    s.openOverlay(kAal, o);
    const nlohmann::json saved = s.state()["overlay"];
    EXPECT_EQ(saved["file"], kAal);
    EXPECT_EQ(saved["labels"], true);
    EXPECT_EQ(saved["label_table"], kAalNames);
    EXPECT_DOUBLE_EQ(saved["alpha"].get<double>(), 0.6);
    EXPECT_TRUE(saved["window"].is_null());
    s.saveState(path);
  }
  Session r("native");
  openCh2(r);
  ASSERT_EQ(r.overlay(), nullptr);
  r.loadState(path);
  ASSERT_NE(r.overlay(), nullptr);
  EXPECT_EQ(r.overlay()->name, kAal);
  EXPECT_TRUE(r.overlay()->fused->labels);
  EXPECT_DOUBLE_EQ(r.overlay()->fused->opacity, 0.6);
  EXPECT_EQ(r.overlay()->labels.labels.size(), 116u);  // aal.nii.txt names 116 regions
  EXPECT_EQ(r.probe({40.0, -25.0, 52.0}).labelName, "Postcentral_R");
  EXPECT_EQ(r.probe({-40.0, -25.0, 52.0}).labelName, "Postcentral_L");
}

TEST(FusionState, SameFileIsRestyledNotReadAgainAndKeptWithoutOne) {
  if (!haveMricron()) GTEST_SKIP() << "mricron templates not installed";
  Session s("native");
  openCh2(s);
  OverlayOptions o;
  o.labels = true;
  o.labelTableText = "58 Postcentral_R\n57 Postcentral_L\n";
  o.labelTableName = "two.txt";
  s.openOverlay(kAal, o);
  const Volume* volume = s.overlay()->fused->volume.get();
  nlohmann::json state = s.state();
  EXPECT_EQ(state["overlay"]["label_table_name"], "two.txt");
  state["overlay"]["alpha"] = 0.25;
  s.restore(state);
  EXPECT_EQ(s.overlay()->fused->volume.get(), volume);  // the same voxels
  EXPECT_DOUBLE_EQ(s.overlay()->fused->opacity, 0.25);
  // The table handed over as text is kept (the state names it only).
  EXPECT_EQ(s.overlay()->labels.labels.size(), 2u);
  EXPECT_EQ(s.probe({40.0, -25.0, 52.0}).labelName, "Postcentral_R");
  // Another look on the same voxels: a colour map with a window.
  state["overlay"]["labels"] = false;
  state["overlay"]["tf"] = "hot";
  state["overlay"]["window"] = {10, 90};
  s.restore(state);
  EXPECT_FALSE(s.overlay()->fused->labels);
  EXPECT_EQ(s.overlay()->fused->window.min, 10.0);
  EXPECT_EQ(s.overlay()->fused->window.max, 90.0);
  EXPECT_EQ(s.state()["overlay"]["window"], nlohmann::json({10.0, 90.0}));
  // A state without one (or from before overlays) keeps it: an overlay given
  // beside a state (tessera view --overlay F --state S) stays.
  s.restore({{"version", state["version"]}, {"settings", state["settings"]}});
  EXPECT_NE(s.overlay(), nullptr);
  state["overlay"] = nullptr;
  s.restore(state);
  EXPECT_NE(s.overlay(), nullptr);
  s.clearOverlay();
  EXPECT_TRUE(s.state()["overlay"].is_null());
}

// The slice views' overlay: every pixel of an axial slice of ch2 through
// z = 52 mm is the anatomy's where the probe finds background, and the
// anatomy's mixed with its label's colour by alpha where it names a region;
// the right postcentral gyrus is on the patient's right (x > 0).
TEST(FusionState, SliceViewPixelsAreTheAnatomyMixedWithTheLabelColour) {
  if (!haveMricron()) GTEST_SKIP() << "mricron templates not installed";
  Session s("native");
  openCh2(s);
  OverlayOptions o;
  o.labels = true;
  o.labelTable = kAalNames;
  o.opacity = 0.6;
  s.openOverlay(kAal, o);
  const Volume& ch2 = s.volume();
  const SliceFrame f = sliceFrame(ch2.direction(), 2);
  const int k = static_cast<int>(std::lround(indexOfWorld(ch2, {40.0, -25.0, 52.0}).z));
  const Image plain = sliceImage(ch2, f, k, ch2.window());
  Image fused = plain;
  fuseSliceImage(fused, ch2, f, k, *s.overlay());
  const SliceRaster r = sliceRaster(f, ch2.dims(), ch2.spacing());
  int named = 0, wrong = 0, rightPostcentral = 0;
  for (int row = 0; row < r.height; ++row) {
    for (int col = 0; col < r.width; ++col) {
      glm::ivec3 v(0);
      v[f.axis] = k;
      v[f.colAxis] = sliceVoxelOf(col, r.pixelMm, ch2.spacing()[f.colAxis], ch2.dims()[f.colAxis],
                                  f.colReversed);
      v[f.rowAxis] = sliceVoxelOf(row, r.pixelMm, ch2.spacing()[f.rowAxis], ch2.dims()[f.rowAxis],
                                  f.rowReversed);
      const ProbeResult p = s.probe(ch2.worldOf(glm::dvec3(v)));
      const std::uint8_t* a = plain.pixel(col, row);
      const std::uint8_t* b = fused.pixel(col, row);
      glm::dvec3 expected(a[0], a[1], a[2]);
      if (p.label > 0) {
        ++named;
        const glm::dvec3 c = s.overlay()->labels.labels.at(p.label).color;
        expected = 0.4 * expected + 0.6 * 255.0 * c;
        if (p.labelName == "Postcentral_R" && p.worldMm.x > 0.0) ++rightPostcentral;
      }
      for (int c = 0; c < 3; ++c) wrong += std::abs(b[c] - expected[c]) > 1.5 ? 1 : 0;
    }
  }
  std::printf("axial slice %d: %d pixels labelled, %d right postcentral, %d channels off\n", k,
              named, rightPostcentral, wrong);
  EXPECT_GT(named, 5000);
  EXPECT_GT(rightPostcentral, 100);
  EXPECT_EQ(wrong, 0);
}

// With an interactive view (the viewers), an ES 2 profile refuses the
// overlay up front, and the previous state stays.
TEST(FusionState, AViewOnEs2RefusesTheOverlay) {
  if (!haveMricron()) GTEST_SKIP() << "mricron templates not installed";
  Session s("webgl1");
  openCh2(s);
  s.view();
  OverlayOptions o;
  o.labels = true;
  std::string message;
  try {
    s.openOverlay(kAal, o);
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("needs 3D textures"), std::string::npos) << message;
  EXPECT_EQ(s.overlay(), nullptr);
}

TEST(FusionState, BadOverlayValuesAreNamed) {
  if (!haveMricron()) GTEST_SKIP() << "mricron templates not installed";
  Session s("native");
  openCh2(s);
  nlohmann::json state = s.state();
  state["overlay"] = {{"file", kAal}, {"alpha", "half"}};
  EXPECT_NE(messageOf(s, state).find("overlay.alpha: expected a number"), std::string::npos)
      << messageOf(s, state);
  state["overlay"] = {{"file", kAal}, {"alpha", 2.0}};
  EXPECT_NE(messageOf(s, state).find("--overlay-opacity"), std::string::npos)
      << messageOf(s, state);
  state["overlay"] = {{"file", kAal}, {"window", {1}}};
  EXPECT_NE(messageOf(s, state).find("overlay.window: expected [lo, hi]"), std::string::npos);
  state["overlay"] = {{"alpha", 0.5}};
  EXPECT_NE(messageOf(s, state).find("overlay.file: missing"), std::string::npos);
  state["overlay"] = {{"file", "/nonexistent/pet.nii.gz"}};
  const std::string missing = messageOf(s, state);
  EXPECT_NE(missing.find("session state: overlay /nonexistent/pet.nii.gz"), std::string::npos)
      << missing;
  EXPECT_EQ(s.overlay(), nullptr);
}

}  // namespace
}  // namespace tessera::session
