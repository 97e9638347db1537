// A second volume over an OME-Zarr store (docs/fusion.md): aal over a ch2
// store (written as `tessera convert` writes it), read in core and streamed
// brick by brick, fused in the same ray march and aligned by world
// coordinates: the GPU frame equals the CPU reference, equals the frame of
// the file it came from, and the crosshair's probe names the postcentral
// gyri on the right sides, reading the store's own voxels.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "support/MricronAtlas.h"
#include "support/TestSupport.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/io/ZarrWriter.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/session/Session.h"

namespace tessera::session {
namespace {

using test::aalLabels;
using test::haveMricron;
using test::kAal;
using test::kAalNames;
using test::kCh2;
constexpr int kSize = 128;

// ch2 (a file or its store) from the patient's right, cut open at x = +32 mm.
void look(Session& s, const std::string& layout) {
  s.settings().tf = TransferFunction::preset("mr-default");
  s.settings().camera.azimuthDeg = 90.0;
  s.settings().camera.elevationDeg = 20.0;
  s.settings().render.clipping.cropMax = {0.68, 1.0, 1.0};
  s.settings().layout = layout;
}

RenderResult renderWithReference(Session& s) {
  RenderRequest req;
  req.settings = s.settings();
  req.width = req.height = kSize;
  req.reference = true;
  return s.run(req);
}

class FusionStore : public test::Ch2StoreSuite {};

TEST_F(FusionStore, AalOverAStoreReadInCoreMatchesTheReferenceAndTheFile) {
  Session file("native");
  look(file, "auto");
  file.open(kCh2);
  file.openOverlay(kAal, aalLabels());
  const RenderResult fromFile = renderWithReference(file);

  Session s("native");
  look(s, "auto");
  s.open(store());
  ASSERT_FALSE(s.streamed());
  s.openOverlay(kAal, aalLabels());
  EXPECT_EQ(s.overlay()->note, "");
  const RenderResult r = renderWithReference(s);
  ASSERT_TRUE(r.psnrDb.has_value());
  const double vsFile = psnr(r.first, fromFile.first);
  std::printf(
      "aal over the ch2 store (in core): GPU vs reference %.2f dB, vs over the file %.2f dB\n",
      *r.psnrDb, vsFile);
  EXPECT_GE(*r.psnrDb, 40.0);
  EXPECT_GE(vsFile, 40.0);
}

TEST_F(FusionStore, AalOverABrickedStoreMatchesTheReference) {
  Session s("native");
  look(s, "bricks");
  s.open(store());
  ASSERT_TRUE(s.streamed());
  s.openOverlay(kAal, aalLabels());
  EXPECT_EQ(s.overlayAnatomy().dims(), glm::ivec3(181, 217, 181));
  const RenderResult fused = renderWithReference(s);
  ASSERT_TRUE(fused.psnrDb.has_value());
  ASSERT_TRUE(fused.bricks.has_value());
  s.clearOverlay();
  const RenderResult plain = renderWithReference(s);
  const double change = psnr(plain.first, fused.first);
  std::printf(
      "aal over the ch2 store (bricks, level %d): GPU vs reference %.2f dB; vs the store "
      "alone %.2f dB\n",
      fused.referenceLevel.value_or(-1), *fused.psnrDb, change);
  EXPECT_GE(*fused.psnrDb, 40.0);
  EXPECT_LT(change, 30.0);  // the atlas shows on the cut face
}

TEST_F(FusionStore, TheProbeOverAStreamedStoreNamesBothSides) {
  Session s("native");
  look(s, "bricks");
  s.open(store());
  ASSERT_TRUE(s.streamed());
  s.openOverlay(kAal, aalLabels());
  const Volume ch2 = readVolume(kCh2);
  // RAS+: the patient's right is +x (core/PatientFrame.h).
  const ProbeResult right = s.probe({40.0, -25.0, 52.0});
  const ProbeResult left = s.probe({-40.0, -25.0, 52.0});
  std::printf("probe over the store: (40, -25, 52) mm %g %s; (-40, -25, 52) mm %g %s\n",
              right.anatomyValue, right.labelName.c_str(), left.anatomyValue,
              left.labelName.c_str());
  EXPECT_EQ(right.labelName, "Postcentral_R");
  EXPECT_EQ(left.labelName, "Postcentral_L");
  const glm::ivec3 i(glm::floor(right.anatomyIndex + 0.5));
  EXPECT_EQ(right.anatomyValue, ch2.valueAt(i.x, i.y, i.z));  // the store's level-0 voxel
  EXPECT_GT(right.anatomyValue, 0.0);
}

}  // namespace
}  // namespace tessera::session
