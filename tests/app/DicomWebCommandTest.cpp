// The CLI on a DICOMweb series in a real PACS (Orthanc, started here):
// `tessera dicomweb ROOT` lists it, `tessera info URL` gives the folder's
// geometry, `tessera render URL` draws the folder's image pixel for pixel
// (the series stored as JPEG 2000 lossless), `tessera convert URL` writes it.
#include <gtest/gtest.h>

#include <cstdlib>
#include <nlohmann/json.hpp>

#include "support/CliRunner.h"
#include "support/OrthancServer.h"
#include "support/TestSupport.h"
#include "tessera/core/Image.h"

namespace fs = std::filesystem;
using tessera::test::runCli;

TEST(DicomWebCommand, ListsInfoRendersAndConvertsASeriesLikeItsFolder) {
  if (const std::string m = tessera::test::OrthancServer::missing(); !m.empty()) GTEST_SKIP() << m;
  const tessera::test::TempDir tmp;
  const fs::path plain = tmp / "plain";
  const fs::path j2k = tmp / "j2k";
  ASSERT_EQ(runCli("convert gen:shepp-logan:48x40x24 " + plain.string() + "/ --quiet").exitCode, 0);
  const fs::path encode = fs::path(TESSERA_TEST_DATA_DIR) / ".." / "io" / "DicomWebEncode.py";
  ASSERT_EQ(std::system(("/usr/bin/python3 '" + encode.string() + "' '" + plain.string() + "' '" +
                         j2k.string() + "' j2k-lossless 9 >/dev/null 2>&1")
                            .c_str()),
            0);
  tessera::test::OrthancServer orthanc(tmp / "orthanc");
  ASSERT_TRUE(orthanc.upload(j2k));

  const auto list = runCli("dicomweb " + orthanc.dicomWebRoot() + " --json");
  ASSERT_EQ(list.exitCode, 0) << list.err;
  const auto j = nlohmann::json::parse(list.out);
  ASSERT_EQ(j["studies"].size(), 1u) << list.out;
  ASSERT_EQ(j["studies"][0]["series"].size(), 1u) << list.out;
  EXPECT_EQ(j["studies"][0]["series"][0]["instances"], 24);
  const std::string url = j["studies"][0]["series"][0]["url"];
  const auto table = runCli("dicomweb " + orthanc.dicomWebRoot());
  EXPECT_NE(table.out.find(url), std::string::npos) << table.out;

  const auto folderInfo = nlohmann::json::parse(runCli("info " + plain.string() + " --json").out);
  const auto webInfo = runCli("info " + url + " --json");
  ASSERT_EQ(webInfo.exitCode, 0) << webInfo.err;
  const auto w = nlohmann::json::parse(webInfo.out);
  EXPECT_EQ(w["dims"], folderInfo["dims"]);
  EXPECT_EQ(w["affine"], folderInfo["affine"]);
  EXPECT_EQ(w["value_min"], folderInfo["value_min"]);
  EXPECT_EQ(w["value_max"], folderInfo["value_max"]);

  const std::string view = " --size 128x128 --azimuth 30 --elevation 20";
  ASSERT_EQ(
      runCli("render " + plain.string() + view + " --out " + (tmp / "f.png").string()).exitCode, 0);
  const auto r = runCli("render " + url + view + " --out " + (tmp / "w.png").string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const tessera::Image a = tessera::Image::readPng(tmp / "f.png");
  const tessera::Image b = tessera::Image::readPng(tmp / "w.png");
  ASSERT_EQ(a.width(), b.width());
  EXPECT_TRUE(a.rgba() == b.rgba()) << "the DICOMweb render differs from the folder's";

  const auto c = runCli("convert " + url + " " + (tmp / "out.nii.gz").string() + " --quiet");
  ASSERT_EQ(c.exitCode, 0) << c.err;
  const auto n =
      nlohmann::json::parse(runCli("info " + (tmp / "out.nii.gz").string() + " --json").out);
  EXPECT_EQ(n["dims"], folderInfo["dims"]);

  // A series that is not there: exit 1, one line naming the URL.
  const std::string missing = url.substr(0, url.rfind('/') + 1) + "1.2.3";
  const auto bad = runCli("info " + missing);
  EXPECT_EQ(bad.exitCode, 1);
  EXPECT_EQ(bad.err, "tessera: error: " + missing +
                         "/metadata: HTTP 404 Not Found: no such study, "
                         "series or instance, or not a DICOMweb service root\n");
}
