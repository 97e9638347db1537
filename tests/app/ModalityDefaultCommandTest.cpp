// `tessera render` of a DICOM series without --tf: the modality picks the
// transfer function (session/ModalityDefault.h). A CT opens with
// ct-soft-tissue, whose window is in HU, so two CTs of one anatomy stored
// with other rescales render alike, and the default render is the one with
// --tf ct-soft-tissue, pixel for pixel; an MR opens with mr-percentile; a
// NIfTI draws what it drew before (mr-default); --tf always wins.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "support/CliRunner.h"
#include "support/TestSupport.h"
#include "tessera/core/Image.h"
#include "tessera/io/DicomSeriesReader.h"
#include "tessera/reference/ImageMetrics.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;
using test::runCli;

constexpr const char* kView = " --size 96x96 --azimuth 30 --elevation 20";

// A 40^3 body in HU: air around a ball of soft tissue (40 HU) in a layer of
// fat (-100 HU) around a bone core (800 HU).
Volume huPhantom() {
  Volume v = Volume::allocate({40, 40, 40}, ScalarType::I16, "phantom");
  for (int z = 0; z < 40; ++z) {
    for (int y = 0; y < 40; ++y) {
      for (int x = 0; x < 40; ++x) {
        const double r = std::hypot(x - 19.5, y - 19.5, z - 19.5);
        const double hu = r > 17 ? -1000 : r > 14 ? -100 : r > 6 ? 40 : 800;
        v.setValueAtIndex(v.index(x, y, z), hu);
      }
    }
  }
  v.invalidateRange();
  return v;
}

// An MR: arbitrary units, a bright ball and a few hot voxels (vessels) that
// a window on the value range would let dominate.
Volume mrPhantom() {
  Volume v = Volume::allocate({40, 40, 40}, ScalarType::U16, "mr");
  for (int z = 0; z < 40; ++z) {
    for (int y = 0; y < 40; ++y) {
      for (int x = 0; x < 40; ++x) {
        const double r = std::hypot(x - 19.5, y - 19.5, z - 19.5);
        const bool hot = (x * 7 + y * 13 + z * 3) % 331 == 0;  // 0.3 %: above the 99th percentile
        v.setValueAtIndex(v.index(x, y, z), hot ? 4000 : r > 16 ? 20 : 300 + 20 * (x % 5));
      }
    }
  }
  v.invalidateRange();
  return v;
}

fs::path writeSeries(const Volume& v, const fs::path& folder, const std::string& modality,
                     double slope, double intercept) {
  DicomWriteOptions o;
  o.modality = modality;
  o.rescaleSlope = slope;
  o.rescaleIntercept = intercept;
  writeDicomSeries(v, folder, o);
  return folder;
}

// Renders `args` (which must succeed) into `png` and returns the image and
// what the command wrote to stderr.
std::pair<Image, std::string> render(const std::string& args, const fs::path& png) {
  const test::CliRun r = runCli("render " + args + kView + " --out " + png.string());
  EXPECT_EQ(r.exitCode, 0) << args << ": " << r.err;
  return {Image::readPng(png), r.err};
}

// The fraction of pixels that are not the black background.
double covered(const Image& image) {
  const auto& px = image.rgba();
  std::size_t lit = 0;
  for (std::size_t i = 0; i < px.size(); i += 4) lit += (px[i] | px[i + 1] | px[i + 2]) != 0;
  return static_cast<double>(lit) / static_cast<double>(px.size() / 4);
}

TEST(ModalityDefaultCommand, CtRendersWithCtSoftTissueWhateverItsStoredRange) {
  const test::TempDir tmp;
  const Volume body = huPhantom();
  // Stored (HU + 1024) * 2, and HU + 1000: neither stored range is HU.
  const fs::path a = writeSeries(body, tmp / "a", "CT", 0.5, -1024);
  const fs::path b = writeSeries(body, tmp / "b", "CT", 1.0, -1000);

  const auto [def, note] = render(a.string(), tmp / "default.png");
  EXPECT_NE(note.find("tessera: note: CT: default transfer function ct-soft-tissue (modality CT), "
                      "window -160..240 HU of the preset; --tf to change"),
            std::string::npos)
      << note;
  const auto [named, namedNote] = render(a.string() + " --tf ct-soft-tissue", tmp / "named.png");
  EXPECT_TRUE(def.rgba() == named.rgba()) << "the CT default differs from --tf ct-soft-tissue";
  EXPECT_EQ(namedNote.find("default transfer function"), std::string::npos) << namedNote;

  const auto [other, otherNote] = render(b.string(), tmp / "other.png");
  const double sameAnatomy = psnr(def, other);
  EXPECT_GE(sameAnatomy, 50.0) << "two rescales of one CT render apart";
  RecordProperty("psnr_ct_rescales", std::to_string(sameAnatomy));

  // What main drew before: mr-default over the value range, another image.
  const auto [before, beforeNote] = render(a.string() + " --tf mr-default", tmp / "before.png");
  const double change = psnr(def, before);
  EXPECT_LT(change, 30.0);
  EXPECT_GT(covered(def), 0.1);  // the soft tissue and bone are drawn, not a blank frame
  RecordProperty("psnr_ct_default_vs_mr_default", std::to_string(change));
}

TEST(ModalityDefaultCommand, TfGivenWinsAndANiftiKeepsTodaysDefault) {
  const test::TempDir tmp;
  const fs::path ct = writeSeries(huPhantom(), tmp / "ct", "CT", 0.5, -1024);
  const fs::path nii = tmp / "ct.nii.gz";
  ASSERT_EQ(runCli("convert " + ct.string() + " " + nii.string() + " --quiet").exitCode, 0);

  // --tf grey on the CT draws what --tf grey draws on its NIfTI copy.
  const auto [grey, greyNote] = render(ct.string() + " --tf grey", tmp / "grey.png");
  EXPECT_EQ(greyNote.find("default transfer function"), std::string::npos) << greyNote;
  const auto [greyNii, unused] = render(nii.string() + " --tf grey", tmp / "grey-nii.png");
  EXPECT_TRUE(grey.rgba() == greyNii.rgba()) << "PSNR " << psnr(grey, greyNii);
  const auto [def, defNote] = render(ct.string(), tmp / "default.png");
  EXPECT_LT(psnr(grey, def), 30.0);

  // The NIfTI has no modality: mr-default, as before.
  const auto [niiDefault, niiNote] = render(nii.string(), tmp / "nii.png");
  EXPECT_EQ(niiNote.find("default transfer function"), std::string::npos) << niiNote;
  const auto [niiNamed, unused2] = render(nii.string() + " --tf mr-default", tmp / "nii-mr.png");
  EXPECT_TRUE(niiDefault.rgba() == niiNamed.rgba());
  const nlohmann::json j = test::runCliJson("render " + nii.string() + kView + " --json --out " +
                                            (tmp / "nii-json.png").string());
  EXPECT_EQ(j["tf"], "mr-default");
}

TEST(ModalityDefaultCommand, MrRendersWithMrPercentile) {
  const test::TempDir tmp;
  const fs::path mr = writeSeries(mrPhantom(), tmp / "mr", "MR", 1.0, 0.0);
  const auto [def, note] = render(mr.string(), tmp / "default.png");
  EXPECT_NE(note.find("MR: default transfer function mr-percentile (modality MR), window "),
            std::string::npos)
      << note;
  const auto [named, unused] = render(mr.string() + " --tf mr-percentile", tmp / "named.png");
  EXPECT_TRUE(def.rgba() == named.rgba()) << "the MR default differs from --tf mr-percentile";
  // mr-default over the value range, which the hot voxels stretch.
  const auto [range, unused2] = render(mr.string() + " --tf mr-default", tmp / "range.png");
  const double change = psnr(def, range);
  EXPECT_LT(change, 30.0);
  RecordProperty("psnr_mr_percentile_vs_range", std::to_string(change));
}

TEST(ModalityDefaultCommand, InfoShowsTheModality) {
  const test::TempDir tmp;
  const fs::path ct = writeSeries(huPhantom(), tmp / "ct", "CT", 0.5, -1024);
  const fs::path mr = writeSeries(mrPhantom(), tmp / "mr", "MR", 1.0, 0.0);
  const fs::path nii = tmp / "ct.nii.gz";
  ASSERT_EQ(runCli("convert " + ct.string() + " " + nii.string() + " --quiet").exitCode, 0);
  EXPECT_EQ(test::runCliJson("info " + ct.string() + " --json")["modality"], "CT");
  EXPECT_EQ(test::runCliJson("info " + mr.string() + " --json")["modality"], "MR");
  EXPECT_EQ(test::runCliJson("info " + nii.string() + " --json")["modality"], "");
  const test::CliRun text = runCli("info " + ct.string());
  EXPECT_NE(text.out.find("\nmodality    CT\n"), std::string::npos) << text.out;
  EXPECT_NE(runCli("info " + nii.string()).out.find("\nmodality    unknown\n"), std::string::npos);
}

// The slice a clinician looks at first: a CT's in the soft-tissue window
// (the default preset's HU), as the render classifies it; a NIfTI's in its
// value range, as before.
TEST(ModalityDefaultCommand, SliceOfACtShowsTheSoftTissueWindow) {
  const test::TempDir tmp;
  const fs::path ct = writeSeries(huPhantom(), tmp / "ct", "CT", 0.5, -1024);
  const fs::path nii = tmp / "ct.nii.gz";
  ASSERT_EQ(runCli("convert " + ct.string() + " " + nii.string() + " --quiet").exitCode, 0);
  const std::string args = " --axis z --index 20 --json --out " + (tmp / "s.png").string();
  EXPECT_EQ(test::runCliJson("slice " + ct.string() + args)["window"],
            nlohmann::json::array({-160, 240}));
  EXPECT_EQ(test::runCliJson("slice " + ct.string() + args + " --tf ct-lung")["window"],
            nlohmann::json::array({-1350, 150}));
  EXPECT_EQ(test::runCliJson("slice " + ct.string() + args + " --window -1000 1000")["window"],
            nlohmann::json::array({-1000, 1000}));
  EXPECT_EQ(test::runCliJson("slice " + nii.string() + args)["window"],
            nlohmann::json::array({-1000, 800}));
}

}  // namespace
}  // namespace tessera
