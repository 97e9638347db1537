// The modality picks the TF a volume opens with when the user named none
// (session/ModalityDefault.h): CT -> ct-soft-tissue over its HU window
// unless the series has its own window, MR -> mr-percentile, anything else
// keeps the front end's TF; a TF the user named always stays, and a
// clinical one gets its window on any volume.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include <nlohmann/json.hpp>

#include "support/ExpectError.h"
#include "support/TestSupport.h"
#include "tessera/core/ClinicalPresets.h"
#include "tessera/io/DicomSeriesReader.h"
#include "tessera/session/ModalityDefault.h"
#include "tessera/session/Session.h"

namespace tessera::session {
namespace {

// 16x16x8 HU from -1000 to 1000 along x, with `modality`.
std::shared_ptr<Volume> huRamp(const std::string& modality) {
  auto v = std::make_shared<Volume>(Volume::allocate({16, 16, 8}, ScalarType::I16, "ramp"));
  for (std::size_t i = 0; i < v->voxelCount(); ++i) {
    v->setValueAtIndex(i, std::round(-1000.0 + 2000.0 * static_cast<double>(i % 16) / 15.0));
  }
  v->invalidateRange();
  v->setModality(modality);
  return v;
}

void expectWindow(const Volume& v, double lo, double hi) {
  EXPECT_EQ(v.window().min, lo);
  EXPECT_EQ(v.window().max, hi);
}

TEST(ModalityDefault, CtWithoutItsOwnWindowOpensWithCtSoftTissueOverItsHuWindow) {
  Session s;
  s.setVolume(huRamp("CT"));
  EXPECT_EQ(s.settings().tf.name, "ct-soft-tissue");
  expectWindow(s.volume(), -160, 240);
  EXPECT_EQ(s.defaultNote(),
            "CT: default transfer function ct-soft-tissue (modality CT), window -160..240 HU of "
            "the preset; --tf to change");
}

TEST(ModalityDefault, TheSeriesOwnWindowTakesPrecedenceOverThePresets) {
  Session s;
  auto ct = huRamp("CT");
  ct->setWindow({-500, 1300});  // Window Center/Width 400/1800 from the series
  s.setVolume(ct);
  EXPECT_EQ(s.settings().tf.name, "ct-soft-tissue");
  expectWindow(s.volume(), -500, 1300);
  EXPECT_NE(s.defaultNote().find("the volume's own window 400/1800 (centre/width)"),
            std::string::npos)
      << s.defaultNote();
}

TEST(ModalityDefault, MrOpensWithMrPercentileOverItsPercentiles) {
  Session s;
  auto mr = huRamp("MR");
  const ValueRange expected = clinicalWindow(clinicalPreset("mr-percentile"), *mr);
  ASSERT_GT(expected.min, -1000);  // the 1st percentile is above the minimum
  s.setVolume(mr);
  EXPECT_EQ(s.settings().tf.name, "mr-percentile");
  expectWindow(s.volume(), expected.min, expected.max);
  EXPECT_NE(s.defaultNote().find("mr-percentile (modality MR)"), std::string::npos);
}

TEST(ModalityDefault, OtherModalitiesAndNoneKeepTheFrontEndsTf) {
  for (const std::string modality : {"", "PT", "US"}) {
    Session s;
    s.setVolume(huRamp(modality));
    EXPECT_EQ(s.settings().tf.name, "mr-default") << modality;
    EXPECT_FALSE(s.volume().hasWindow()) << modality;  // the value range
    EXPECT_EQ(s.defaultNote(), "") << modality;
  }
}

TEST(ModalityDefault, ATfTheUserNamedStaysAndAClinicalOneGetsItsWindowOnAnyVolume) {
  Session s;
  s.settings().tf = TransferFunction::preset("grey");
  s.settings().tfIsDefault = false;
  s.setVolume(huRamp("CT"));
  EXPECT_EQ(s.settings().tf.name, "grey");
  EXPECT_FALSE(s.volume().hasWindow());
  EXPECT_EQ(s.defaultNote(), "");

  Session lung;
  lung.settings().tf = TransferFunction::fromPresetOrFile("ct-lung");
  lung.settings().tfIsDefault = false;
  lung.setVolume(huRamp(""));  // a NIfTI CT: no modality, values in HU
  EXPECT_EQ(lung.settings().tf.name, "ct-lung");
  expectWindow(lung.volume(), -1350, 150);
}

TEST(ModalityDefault, TheUsersWindowWinsOverThePresets) {
  Session s;
  s.settings().window = ValueRange{-300, 300};
  s.setVolume(huRamp("CT"));
  EXPECT_EQ(s.settings().tf.name, "ct-soft-tissue");
  expectWindow(s.volume(), -300, 300);
}

TEST(ModalityDefault, AVolumeWithoutModalityAfterACtGetsTheFrontEndsTfBack) {
  Session s;
  s.setVolume(huRamp("CT"));
  ASSERT_EQ(s.settings().tf.name, "ct-soft-tissue");
  s.setVolume(huRamp(""));
  EXPECT_EQ(s.settings().tf.name, "mr-default");
  EXPECT_FALSE(s.volume().hasWindow());
}

TEST(ModalityDefault, AStatesTfIsTheUsersChoice) {
  EXPECT_TRUE(Settings().tfIsDefault);
  nlohmann::json state = Settings().toJson();
  EXPECT_FALSE(Settings::fromJson(state).tfIsDefault);
  state.erase("tf");
  EXPECT_TRUE(Settings::fromJson(state).tfIsDefault);
}

TEST(ModalityDefault, ClinicalPresetWindowIsForClinicalPresetsOnly) {
  const Volume ct = *huRamp("CT");
  EXPECT_FALSE(clinicalPresetWindow(TransferFunction::preset("grey"), ct));
  // ct-bone is the older ramp on the volume's own window; the HU bone
  // preset has its own name, ct-bone-hu, and its window.
  EXPECT_FALSE(clinicalPresetWindow(TransferFunction::preset("ct-bone"), ct));
  const std::optional<ValueRange> bone =
      clinicalPresetWindow(TransferFunction::preset("ct-bone-hu"), ct);
  ASSERT_TRUE(bone);
  EXPECT_EQ(bone->min, -1000);
  EXPECT_EQ(bone->max, 3000);
  const std::optional<ValueRange> angio =
      clinicalPresetWindow(TransferFunction::preset("ct-angio"), ct);
  ASSERT_TRUE(angio);
  EXPECT_EQ(angio->min, -200);
  EXPECT_EQ(angio->max, 800);
}

// The interactive front ends: the page hands its volume over (setVolume
// with a view), the desktop opens a pyramid in the view (openInView); both
// show the default in the TF editor and the HU window on the view.
TEST(ModalityDefault, TheViewShowsTheDefaultWhenTheVolumeIsHandedOverOrOpenedInIt) {
  Session page;
  page.view();
  page.setVolume(huRamp("CT"));
  EXPECT_EQ(page.view().tfEditor().transferFunction().name, "ct-soft-tissue");
  EXPECT_EQ(page.view().window().min, -160);
  EXPECT_EQ(page.view().window().max, 240);

  const test::TempDir dir;
  DicomWriteOptions o;
  o.modality = "CT";
  o.rescaleSlope = 0.5;
  o.rescaleIntercept = -1024;
  writeDicomSeries(*huRamp(""), dir.path(), o);
  Session desktop;
  desktop.openInView(dir.path().string());
  EXPECT_EQ(desktop.view().tfEditor().transferFunction().name, "ct-soft-tissue");
  EXPECT_EQ(desktop.view().window().min, -160);
  EXPECT_EQ(desktop.view().window().max, 240);
  EXPECT_NE(desktop.defaultNote().find("ct-soft-tissue"), std::string::npos);
}

// A preset picked from the desktop's or the page's menu goes through the
// session (Session::choosePreset): a clinical one brings its window to the
// volume and the view, another gives the volume's own window back, a
// user's window stays; on a CT, ct-bone gets a note naming ct-bone-hu.
TEST(ModalityDefault, APresetChosenFromAMenuSetsItsWindowThroughTheSession) {
  Session s;
  s.view();
  s.setVolume(huRamp("CT"));
  s.choosePreset("ct-bone-hu");
  EXPECT_EQ(s.settings().tf.name, "ct-bone-hu");
  EXPECT_FALSE(s.settings().tfIsDefault);
  EXPECT_EQ(s.view().tfEditor().transferFunction().name, "ct-bone-hu");
  expectWindow(s.volume(), -1000, 3000);
  EXPECT_EQ(s.view().window().min, -1000);
  EXPECT_EQ(s.view().window().max, 3000);
  s.choosePreset("ct-lung");
  expectWindow(s.volume(), -1350, 150);
  EXPECT_EQ(s.view().window().min, -1350);
  EXPECT_EQ(s.view().window().max, 150);
  EXPECT_EQ(s.defaultNote(), "");
  // Not clinical: the volume's value range again (rule 4).
  s.choosePreset("ct-bone");
  expectWindow(s.volume(), -1000, 1000);
  EXPECT_EQ(s.view().window().min, -1000);
  EXPECT_EQ(s.view().window().max, 1000);
  EXPECT_EQ(s.defaultNote(),
            "CT: ct-bone is the bone ramp over the volume's own window; the bone preset in "
            "Hounsfield units, the same on every CT, is ct-bone-hu");
  // The user's window wins over the preset's.
  Settings mine = s.settings();
  mine.window = ValueRange{-50, 50};
  s.setSettings(mine);
  s.choosePreset("ct-angio");
  expectWindow(s.volume(), -50, 50);
  EXPECT_EQ(s.view().window().min, -50);
  // An unknown name changes nothing and names the presets.
  const std::string m = test::inputErrorMessage([&] { s.choosePreset("ct-nothing"); });
  EXPECT_NE(m.find("ct-bone-hu"), std::string::npos) << m;
  EXPECT_EQ(s.settings().tf.name, "ct-angio");
}

}  // namespace
}  // namespace tessera::session
