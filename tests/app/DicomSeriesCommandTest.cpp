// A DICOM folder as scanners leave it: slice files with meaningless names,
// a second series and a stray text file beside them. `tessera info` must
// find the right volume and `tessera render` must draw what the same volume
// as NIfTI draws (the DICOM reader's acceptance, on ch2 when mricron-data is there).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <nlohmann/json.hpp>

#include "support/CliRunner.h"
#include "support/TestSupport.h"
#include "tessera/core/Image.h"
#include "tessera/reference/ImageMetrics.h"

namespace fs = std::filesystem;
using tessera::test::runCli;

namespace {

std::string sourceVolume() {
  const char* ch2 = "/usr/share/mricron/templates/ch2.nii.gz";
  return fs::exists(ch2) ? ch2 : "gen:shepp-logan:96x112x80";
}

// Moves every file of `from` into `to` under a random hexadecimal name.
void shuffleInto(const fs::path& from, const fs::path& to, std::mt19937& rng) {
  for (const auto& entry : fs::directory_iterator(from)) {
    char name[17];
    std::snprintf(name, sizeof name, "%08x%08x", static_cast<unsigned>(rng()),
                  static_cast<unsigned>(rng()));
    fs::rename(entry.path(), to / name);
  }
}

}  // namespace

TEST(DicomSeriesCommand, MixedFolderWithShuffledNamesReadsAndRendersLikeTheNifti) {
  const tessera::test::TempDir tmp;
  const std::string source = sourceVolume();
  const fs::path mixed = tmp / "mixed";
  fs::create_directory(mixed);
  std::mt19937 rng(7);
  ASSERT_EQ(runCli("convert " + source + " " + (tmp / "main/").string() + " --quiet").exitCode, 0);
  ASSERT_EQ(runCli("convert gen:sphere:40 " + (tmp / "other/").string() + " --quiet").exitCode, 0);
  shuffleInto(tmp / "main", mixed, rng);
  shuffleInto(tmp / "other", mixed, rng);
  std::ofstream(mixed / "notes.txt") << "not a DICOM file\n";

  const auto expected = runCli("info " + source + " --json");
  const auto info = runCli("info " + mixed.string() + " --json");
  ASSERT_EQ(info.exitCode, 0) << info.err;
  const auto e = nlohmann::json::parse(expected.out);
  const auto j = nlohmann::json::parse(info.out);
  EXPECT_EQ(j["dims"], e["dims"]);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(j["spacing"][axis].get<double>(), e["spacing"][axis].get<double>(), 1e-6);
  }
  EXPECT_EQ(j["value_min"], e["value_min"]);
  EXPECT_EQ(j["value_max"], e["value_max"]);
  ASSERT_EQ(j["dicom_series"].size(), 2u) << info.out;
  EXPECT_NE(j["description"].get<std::string>().find("skipped 1 non-DICOM file"), std::string::npos)
      << j["description"];

  // The other series by its UID.
  const std::string otherUid = j["dicom_series"][1]["series_instance_uid"];
  const auto other = runCli("info " + mixed.string() + " --json --series " + otherUid);
  ASSERT_EQ(other.exitCode, 0) << other.err;
  EXPECT_EQ(nlohmann::json::parse(other.out)["dims"], nlohmann::json::array({40, 40, 40}));

  // mr-default on both: the DICOM copy is an MR series, whose own default
  // would be mr-percentile (session/ModalityDefault.h).
  const std::string view = " --size 160x160 --azimuth 30 --elevation 20 --tf mr-default";
  const auto fromNifti = tmp / "nifti.png";
  const auto fromDicom = tmp / "dicom.png";
  ASSERT_EQ(runCli("render " + source + view + " --out " + fromNifti.string()).exitCode, 0);
  const auto r = runCli("render " + mixed.string() + view + " --out " + fromDicom.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const double psnr =
      tessera::psnr(tessera::Image::readPng(fromNifti), tessera::Image::readPng(fromDicom));
  EXPECT_GE(psnr, 45.0);
  RecordProperty("psnr_dicom_vs_nifti", std::to_string(psnr));
}
