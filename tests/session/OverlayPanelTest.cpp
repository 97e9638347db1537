// The overlay panel's logic (session/OverlayPanel.h), driven with the calls
// and arguments the desktop viewer's panel makes (PanelsOverlay.cpp): "Add
// overlay", a control changed (alpha, a colour map), "Remove overlay" each
// change the frame as they should, every frame equal to the CPU reference
// of the same look, and removing it gives back the anatomy's frame exactly.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "support/MricronAtlas.h"
#include "tessera/core/Error.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/session/OverlayPanel.h"
#include "tessera/session/Session.h"

namespace tessera::session {
namespace {

using test::haveMricron;
using test::kAal;
using test::kAalNames;
using test::kCh2;
constexpr int kSize = 128;

// Pixels whose colour differs by more than `tol` in any channel.
int differing(const Image& a, const Image& b, int tol = 2) {
  int n = 0;
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) {
      const std::uint8_t* p = a.pixel(x, y);
      const std::uint8_t* q = b.pixel(x, y);
      for (int c = 0; c < 3; ++c) {
        if (std::abs(int(p[c]) - int(q[c])) > tol) {
          ++n;
          break;
        }
      }
    }
  }
  return n;
}

// ch2 from the patient's right, cut open at x = +32 mm (FusionTest.cpp).
void openCh2(Session& s) {
  s.settings().tf = TransferFunction::preset("mr-default");
  s.settings().camera.azimuthDeg = 90.0;
  s.settings().camera.elevationDeg = 20.0;
  s.settings().render.clipping.cropMax = {0.68, 1.0, 1.0};
  s.open(kCh2);
}

// The frame and its reference (the same look on the CPU).
double psnrToReference(Session& s, const Image& frame) {
  return psnr(frame, s.renderReference(kSize, kSize));
}

TEST(OverlayPanel, AddRestyleRemoveChangeTheFrameAsTheyShould) {
  if (!haveMricron()) GTEST_SKIP() << "mricron templates not installed";
  Session s("native");
  openCh2(s);
  const Image anatomy = s.render(kSize, kSize);

  OverlayControls c;  // what the panel holds: labels with aal's table, alpha 0.6
  c.labels = true;
  c.table = kAalNames;
  c.alpha = 0.6f;
  addOverlayFromPanel(s, kAal, c);
  ASSERT_NE(s.overlay(), nullptr);
  EXPECT_EQ(overlayPanelLine(*s.overlay()), "aal.nii.gz 181x217x181: 116 labels");
  const Image added = s.render(kSize, kSize);
  const double addedDb = psnrToReference(s, added);
  const int addedPixels = differing(anatomy, added);
  std::printf("add: %d of %d pixels changed, GPU vs reference %.2f dB\n", addedPixels,
              kSize * kSize, addedDb);
  EXPECT_GE(addedDb, 40.0);
  EXPECT_GT(addedPixels, kSize * kSize / 50);  // the cut face is coloured

  c.alpha = 1.0f;  // the alpha slider
  EXPECT_TRUE(restyleOverlayFromPanel(s, c));
  const Image opaque = s.render(kSize, kSize);
  const double opaqueDb = psnrToReference(s, opaque);
  const int opaquePixels = differing(added, opaque);
  std::printf("alpha 0.6 -> 1: %d pixels changed, GPU vs reference %.2f dB\n", opaquePixels,
              opaqueDb);
  EXPECT_GE(opaqueDb, 40.0);
  EXPECT_GT(opaquePixels, 0);
  EXPECT_LE(opaquePixels, addedPixels + kSize * kSize / 100);  // only where the atlas shows
  EXPECT_EQ(s.overlay()->options.opacity, 1.0);

  c.labels = false;  // the same volume as values, colour map hot
  c.colourMap = 0;
  EXPECT_TRUE(restyleOverlayFromPanel(s, c));
  EXPECT_EQ(overlayPanelLine(*s.overlay()), "aal.nii.gz 181x217x181: colour map hot");
  const Image hot = s.render(kSize, kSize);
  const double hotDb = psnrToReference(s, hot);
  std::printf("labels -> hot: %d pixels changed, GPU vs reference %.2f dB\n",
              differing(opaque, hot), hotDb);
  EXPECT_GE(hotDb, 40.0);
  EXPECT_GT(differing(opaque, hot), kSize * kSize / 100);

  removeOverlayFromPanel(s);
  EXPECT_EQ(s.overlay(), nullptr);
  const Image removed = s.render(kSize, kSize);
  std::printf("remove: %d pixels differ from the anatomy's frame\n",
              differing(anatomy, removed, 0));
  EXPECT_EQ(differing(anatomy, removed, 0), 0);
  EXPECT_FALSE(restyleOverlayFromPanel(s, c));  // nothing open: nothing to do
}

TEST(OverlayPanel, ControlsAreTheOptionsTheySay) {
  OverlayControls c;
  c.colourMap = 2;
  c.window = true;
  c.lo = 2.0;
  c.hi = 12.0;
  c.alpha = 0.7f;
  const OverlayOptions o = overlayOptionsOf(c);
  EXPECT_EQ(o.tf, "mr-default");
  EXPECT_FALSE(o.labels);
  ASSERT_TRUE(o.window.has_value());
  EXPECT_EQ(o.window->min, 2.0);
  EXPECT_EQ(o.window->max, 12.0);
  EXPECT_NEAR(o.opacity, 0.7, 1e-6);
  c.colourMap = 9;
  try {
    overlayOptionsOf(c);
    FAIL() << "colour map 9 accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "overlay colour map 9: expected 0..4");
  }
  // The controls follow an overlay opened elsewhere (--overlay, a state).
  Overlay opened;
  opened.options.tf = "ct-bone";
  opened.options.opacity = 0.25;
  opened.options.window = ValueRange{1.0, 3.0};
  OverlayControls synced;
  syncOverlayControls(synced, opened);
  EXPECT_EQ(synced.colourMap, 3);
  EXPECT_FLOAT_EQ(synced.alpha, 0.25f);
  EXPECT_TRUE(synced.window);
  EXPECT_EQ(overlayOptionsOf(synced).tf, "ct-bone");
}

TEST(OverlayPanel, WithoutAVolumeTheSessionSaysWhy) {
  Session s("native");
  OverlayControls c;
  try {
    addOverlayFromPanel(s, "whatever.nii.gz", c);
    FAIL() << "an overlay without a volume was accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "open a volume first: an overlay goes over one");
  }
  try {
    s.addOverlay(std::make_shared<Volume>(Volume::allocate({4, 4, 4}, ScalarType::U8, "v")), "v",
                 {});
    FAIL() << "an overlay without a volume was accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "open a volume first: an overlay goes over one");
  }
}

}  // namespace
}  // namespace tessera::session
