// Clinical defaults measured on DICOM read back: CT presets in Hounsfield
// units give the same opacity to the same HU whatever the stored range and
// rescale (intercept -1024 and 0), where a preset on the volume's own window
// does not; the series' Window Center/Width (first value) is the volume's
// window when present; MR presets take percentiles; the modality picks the
// default.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include <dcmtk/config/osconfig.h>
#include <dcmtk/dcmdata/dcdatset.h>
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>

#include "support/TestSupport.h"
#include "tessera/core/ClinicalPresets.h"
#include "tessera/core/Error.h"
#include "tessera/io/DicomBasicReader.h"
#include "tessera/io/DicomSeriesReader.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

// A 16x16x6 CT whose HU run from `lo` to `hi` along x (integers).
Volume ctRamp(double lo, double hi) {
  Volume v = Volume::allocate({16, 16, 6}, ScalarType::I16, "ct");
  for (std::size_t i = 0; i < v.voxelCount(); ++i) {
    v.setValueAtIndex(i, std::round(lo + (hi - lo) * static_cast<double>(i % 16) / 15.0));
  }
  v.invalidateRange();
  return v;
}

// Written as CT with `intercept`, read back by DCMTK.
Volume roundTrip(const Volume& v, double intercept, const test::TempDir& dir) {
  DicomWriteOptions o;
  o.modality = "CT";
  o.rescaleIntercept = intercept;
  writeDicomSeries(v, dir.path(), o);
  return readDicomSeries(dir.path());
}

TEST(ClinicalDefaults, CtBonePresetGivesTheSameHuTheSameOpacityWhateverTheStoredRange) {
  test::TempDir a;
  test::TempDir b;
  // Stored 0..3048 with intercept -1024 (as most scanners write CT), and
  // stored = HU with intercept 0 over a narrower range.
  const Volume ctA = roundTrip(ctRamp(-1024, 2024), -1024, a);
  const Volume ctB = roundTrip(ctRamp(-1000, 1200), 0, b);
  ASSERT_EQ(ctA.valueRange().min, -1024);
  ASSERT_EQ(ctA.valueRange().max, 2024);
  ASSERT_EQ(ctB.valueRange().min, -1000);
  EXPECT_NE(ctA.description().find("intercept -1024 applied"), std::string::npos);
  const ClinicalPreset& bone = clinicalPreset("ct-bone-hu");
  for (double hu : {-1000.0, 0.0, 150.0, 225.0, 300.0, 700.0, 1000.0, 1200.0}) {
    SCOPED_TRACE(hu);
    EXPECT_DOUBLE_EQ(clinicalOpacity(bone, ctA, hu), clinicalOpacity(bone, ctB, hu));
  }
  EXPECT_EQ(clinicalOpacity(bone, ctA, 0.0), 0.0);             // soft tissue invisible
  EXPECT_NEAR(clinicalOpacity(bone, ctA, 300.0), 0.5, 1e-12);  // the ramp's middle point
  EXPECT_GT(clinicalOpacity(bone, ctA, 700.0), 0.6);           // cortical bone
  // The older ct-bone preset, on each volume's own window, does not agree.
  const TransferFunction old = TransferFunction::preset("ct-bone");
  const auto oldOpacity = [&](const Volume& v, double hu) {
    const ValueRange w = v.window();
    return old.opacity((hu - w.min) / w.width());
  };
  EXPECT_GT(std::abs(oldOpacity(ctA, 700) - oldOpacity(ctB, 700)), 0.1);
}

TEST(ClinicalDefaults, EveryCtPresetIsDefinedInHounsfieldUnits) {
  const Volume any = ctRamp(0, 100);  // its range must not matter
  for (const ClinicalPreset& p : clinicalPresets()) {
    if (p.modality != "CT") continue;
    SCOPED_TRACE(p.name);
    ASSERT_TRUE(p.hounsfield.has_value());
    EXPECT_EQ(clinicalWindow(p, any).min, p.hounsfield->min);
    EXPECT_EQ(clinicalOpacity(p, any, -1000.0), 0.0);  // air is transparent in every CT preset
  }
  // Lung shows parenchyma (-700 HU), angio contrast (300 HU) but not muscle (50 HU).
  EXPECT_GT(clinicalOpacity(clinicalPreset("ct-lung"), any, -700), 0.0);
  EXPECT_GT(clinicalOpacity(clinicalPreset("ct-angio"), any, 300), 0.5);
  EXPECT_EQ(clinicalOpacity(clinicalPreset("ct-angio"), any, 50), 0.0);
  EXPECT_GT(clinicalOpacity(clinicalPreset("ct-soft-tissue"), any, 50), 0.05);
}

TEST(ClinicalDefaults, MrPresetTakesPercentilesOfTheVolume) {
  Volume mr = Volume::allocate({100, 10, 10}, ScalarType::U16, "mr");
  for (std::size_t i = 0; i < mr.voxelCount(); ++i) mr.setValueAtIndex(i, 100 + i % 100);
  mr.setValueAtIndex(0, 60000);  // one bright outlier does not set the window
  mr.invalidateRange();
  const ValueRange w = clinicalWindow(clinicalPreset("mr-percentile"), mr);
  // To within one of the 4096 histogram bins over 100..60000 (14.6 each).
  const double bin = (60000.0 - 100.0) / 4096.0;
  EXPECT_NEAR(w.min, 101, bin);
  EXPECT_NEAR(w.max, 199, bin);
  EXPECT_LT(w.max, 300);  // far from the outlier
}

TEST(ClinicalDefaults, ModalityDecidesTheDefault) {
  ASSERT_NE(defaultClinicalPreset("CT"), nullptr);
  EXPECT_EQ(defaultClinicalPreset("CT")->name, "ct-soft-tissue");
  ASSERT_NE(defaultClinicalPreset("MR"), nullptr);
  EXPECT_EQ(defaultClinicalPreset("MR")->name, "mr-percentile");
  EXPECT_EQ(defaultClinicalPreset("US"), nullptr);
  EXPECT_THROW(clinicalPreset("ct-nothing"), InputError);
}

TEST(ClinicalDefaults, SeriesWindowIsTheVolumesWindowWhenPresent) {
  test::TempDir dir;
  DicomWriteOptions o;
  o.modality = "CT";
  o.rescaleIntercept = -1024;
  writeDicomSeries(ctRamp(-1024, 2024), dir.path(), o);
  {
    const Volume v = readDicomSeries(dir.path());
    EXPECT_FALSE(v.hasWindow());  // none in the files: the value range
  }
  // Two windows (centre 40 width 400, then bone); the first is the default,
  // in rescaled units (HU), not stored ones.
  for (const auto& e : fs::directory_iterator(dir.path())) {
    DcmFileFormat ff;
    ASSERT_TRUE(ff.loadFile(e.path().c_str()).good());
    ASSERT_TRUE(ff.loadAllDataIntoMemory().good());
    ff.getDataset()->putAndInsertString(DCM_WindowCenter, "40\\400");
    ff.getDataset()->putAndInsertString(DCM_WindowWidth, "400\\1800");
    ASSERT_TRUE(ff.saveFile(e.path().c_str(), ff.getDataset()->getOriginalXfer()).good());
  }
  for (const Volume& v : {readDicomSeries(dir.path()), readDicomSeriesBasic(dir.path())}) {
    ASSERT_TRUE(v.hasWindow());
    EXPECT_EQ(v.window().min, -160);
    EXPECT_EQ(v.window().max, 240);
    EXPECT_NE(v.description().find("window 40/400 (centre/width) from the series"),
              std::string::npos)
        << v.description();
  }
}

}  // namespace
}  // namespace tessera
