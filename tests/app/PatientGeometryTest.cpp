// The patient geometry's acceptance: one marked head (bright block on the patient's
// right-anterior-superior side) stored as RAS and LAS NIfTI, LPS NRRD,
// MetaImage with a TransformMatrix, DICOM axial (both slice orders),
// sagittal, coronal and oblique -- written by nibabel, pydicom and
// hand-written headers (tests/geometry/marked_head.py), never by Tessera.
// Every storage renders like the RAS file from three views, and every
// conversion to every format that holds geometry keeps the marker's world
// position, read back by an independent reader (nibabel, pydicom, the
// NRRD/MetaImage/VTI specs).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/CliRunner.h"
#include "support/TestSupport.h"
#include "tessera/core/Image.h"
#include "tessera/reference/ImageMetrics.h"

namespace fs = std::filesystem;
using tessera::test::runCli;

namespace {

const std::string kPython = "/usr/bin/python3";
const std::string kScript = std::string(TESSERA_TEST_DATA_DIR) + "/../geometry/marked_head.py";

bool pythonHasReaders() {
  return std::system((kPython + " -c 'import numpy, nibabel, pydicom' 2>/dev/null").c_str()) == 0;
}

std::string run(const std::string& cmd) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  char buf[4096];
  while (std::size_t n = std::fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  const int status = pclose(p);
  if (status != 0) ADD_FAILURE() << cmd << " failed: " << out;
  return out;
}

// The generated storages, made once for all tests of this file.
class PatientGeometry : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!pythonHasReaders()) return;
    dir_ = new tessera::test::TempDir;
    run(kPython + " " + kScript + " make " + (*dir_ / "in").string());
    std::ifstream f(*dir_ / "in" / "truth.json");
    truth_ = new nlohmann::json(nlohmann::json::parse(f));
  }
  static void TearDownTestSuite() {
    delete truth_;
    delete dir_;
    truth_ = nullptr;
    dir_ = nullptr;
  }
  void SetUp() override {
    if (!truth_) GTEST_SKIP() << kPython << " lacks numpy/nibabel/pydicom (scripts/setup.sh)";
  }
  static fs::path in(const std::string& name) { return *dir_ / "in" / name; }
  static fs::path out(const std::string& name) { return *dir_ / name; }
  static std::vector<std::string> storages() {
    std::vector<std::string> names;
    for (const auto& [name, _] : (*truth_)["storages"].items()) names.push_back(name);
    return names;
  }

  static tessera::test::TempDir* dir_;
  static nlohmann::json* truth_;
};
tessera::test::TempDir* PatientGeometry::dir_ = nullptr;
nlohmann::json* PatientGeometry::truth_ = nullptr;

struct View {
  double azimuth, elevation;
};
constexpr View kViews[] = {{0.0, 0.0}, {90.0, 0.0}, {30.0, 35.0}};

}  // namespace

TEST_F(PatientGeometry, InfoReportsEachStoragesOrientation) {
  for (const std::string& name : storages()) {
    const auto r = runCli("info " + in(name).string() + " --json");
    ASSERT_EQ(r.exitCode, 0) << name << ": " << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["orientation"], (*truth_)["storages"][name]["orientation"]) << name;
  }
}

// Length of a volume's box diagonal (mm), from `info --json`.
double diagonal(const fs::path& file) {
  const auto r = runCli("info " + file.string() + " --json");
  EXPECT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  double sum = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double e = j["dims"][a].get<double>() * j["spacing"][a].get<double>();
    sum += e * e;
  }
  return std::sqrt(sum);
}

TEST_F(PatientGeometry, EveryStorageRendersLikeTheRasFileFromThreeViews) {
  std::printf("  [measured] PSNR vs the RAS NIfTI render (raycast, 160x160)\n");
  std::printf("  [measured] %-22s %-5s %9s %9s %9s\n", "storage", "code", "az0", "az90",
              "az30el35");
  const double rasDiagonal = diagonal(in("ras.nii.gz"));
  for (const std::string& name : storages()) {
    // The camera frames a volume's box: the oblique grid is larger (it holds
    // the whole turned head), so it is zoomed by the ratio of the diagonals
    // to show the anatomy at the same scale.
    const double zoom = diagonal(in(name)) / rasDiagonal;
    std::string row;
    for (const View v : kViews) {
      char view[96];
      std::snprintf(view, sizeof view, "--azimuth %g --elevation %g", v.azimuth, v.elevation);
      auto render = [&](const std::string& file, const fs::path& png) {
        char zoomArg[48];
        std::snprintf(zoomArg, sizeof zoomArg, " --zoom %.9g", file == "ras.nii.gz" ? 1.0 : zoom);
        const auto r = runCli("render " + in(file).string() + " " + view + zoomArg +
                              " --size 160x160 --tf mr-default --out " + png.string());
        EXPECT_EQ(r.exitCode, 0) << file << ": " << r.err;
        return tessera::Image::readPng(png);
      };
      const std::string tag = std::to_string(static_cast<int>(v.azimuth)) + "-" +
                              std::to_string(static_cast<int>(v.elevation));
      const tessera::Image expected = render("ras.nii.gz", out("ras-" + tag + ".png"));
      const tessera::Image got = render(name, out(name + "-" + tag + ".png"));
      const double db = tessera::psnr(got, expected);
      char cell[32];
      std::snprintf(cell, sizeof cell, " %9.2f", db);
      row += cell;
      EXPECT_GE(db, 40.0) << name << " " << view;
    }
    std::printf("  [measured] %-22s %-5s%s\n", name.c_str(),
                (*truth_)["storages"][name]["orientation"].get<std::string>().c_str(), row.c_str());
  }
}

TEST_F(PatientGeometry, ConversionsKeepTheMarkerWhereItIs) {
  const std::vector<std::string> formats = {".nii.gz", ".nrrd", ".mha", ".vti", ".dcm.d"};
  std::vector<std::string> outputs;
  std::map<std::string, std::string> from;
  for (const std::string& name : storages()) {
    for (const std::string& ext : formats) {
      const std::string stem = name.substr(0, name.find('.'));
      const fs::path o = out("conv-" + stem + ext);
      const auto r = runCli("convert " + in(name).string() + " " + o.string() + " --quiet");
      ASSERT_EQ(r.exitCode, 0) << name << " -> " << ext << ": " << r.err;
      outputs.push_back(o.string());
      from[o.string()] = name;
    }
  }
  std::string cmd = kPython + " " + kScript + " marker";
  for (const auto& o : outputs) cmd += " " + o;
  const auto markers = nlohmann::json::parse(run(cmd));
  const auto truth = (*truth_)["marker_ras"];
  std::printf("  [measured] marker centre after conversion, RAS mm (truth %.2f %.2f %.2f)\n",
              truth[0].get<double>(), truth[1].get<double>(), truth[2].get<double>());
  for (const auto& o : outputs) {
    const auto& storageTruth = (*truth_)["storages"][from[o]]["marker_ras"];
    const auto& m = markers[o];
    double worst = 0.0;
    for (int a = 0; a < 3; ++a) {
      worst = std::max(worst, std::abs(m[a].get<double>() - storageTruth[a].get<double>()));
    }
    std::printf("  [measured] %-22s -> %-7s %8.2f %8.2f %8.2f  (off by %.3f mm)\n", from[o].c_str(),
                fs::path(o).filename().string().substr(5).c_str(), m[0].get<double>(),
                m[1].get<double>(), m[2].get<double>(), worst);
    // One voxel of the 2 mm grid.
    EXPECT_LE(worst, 2.0) << from[o] << " -> " << o;
  }
}
