// `tessera convert`: every format round-trips, crop and downsample are
// right, progress goes to stderr, and a failed write leaves nothing behind.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "support/CliRunner.h"
#include "support/TestSupport.h"
#include "tessera/io/NiftiReader.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/io/VolumeWriter.h"

namespace fs = std::filesystem;
using tessera::test::runCli;

namespace {
void expectSameVoxels(const tessera::Volume& a, const tessera::Volume& b) {
  ASSERT_EQ(a.dims(), b.dims());
  ASSERT_EQ(a.type(), b.type());
  for (int axis = 0; axis < 3; ++axis) EXPECT_NEAR(a.spacing()[axis], b.spacing()[axis], 1e-6);
  ASSERT_TRUE(std::equal(a.bytes().begin(), a.bytes().end(), b.bytes().begin()));
}
}  // namespace

// A 4-D NIfTI (nibabel's fMRI example, 2 mm, 3 time points): --time picks
// the volume, the default is the first with a note, and a time point past
// the end is refused naming the file and the count.
TEST(ConvertCommand, TimePointOfA4DNiftiIsConvertedAndOthersAreRefused) {
  const std::string series = "/usr/lib/python3/dist-packages/nibabel/tests/data/example4d.nii.gz";
  if (!fs::exists(series)) GTEST_SKIP() << series << " (python3-nibabel's test data) is missing";
  const tessera::test::TempDir tmp;
  const int timePoints = tessera::niftiTimePoints(tessera::FileSource(series));
  ASSERT_GT(timePoints, 1);
  for (const int t : {0, timePoints - 1}) {
    const auto out = tmp / ("t" + std::to_string(t) + ".nii");
    const auto r = runCli("convert " + series + (t ? " --time " + std::to_string(t) : "") + " " +
                          out.string() + " --quiet");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("note: " + series + ": " + std::to_string(timePoints) +
                         " time points; reading time point " + std::to_string(t)),
              std::string::npos)
        << r.err;
    expectSameVoxels(tessera::readVolume(out.string()), tessera::readNifti(series, t));
  }
  const auto past = runCli("info " + series + " --time " + std::to_string(timePoints));
  EXPECT_EQ(past.exitCode, 1);
  EXPECT_NE(past.err.find(series + ": time point " + std::to_string(timePoints) +
                          " asked for, but the file holds " + std::to_string(timePoints)),
            std::string::npos)
      << past.err;
}

TEST(ConvertCommand, EveryFormatRoundTripsExactly) {
  const tessera::test::TempDir tmp;
  const auto src = tmp / "src.nrrd";
  ASSERT_EQ(runCli("convert gen:shepp-logan:37x29x23 " + src.string() + " --quiet").exitCode, 0);
  const tessera::Volume original = tessera::readVolume(src.string());
  for (const char* name :
       {"a.nii", "a.nii.gz", "a.nrrd", "a.mha", "a.vti", "a.pvm", "a.raw", "dicom/"}) {
    const auto out = tmp / name;
    const auto r = runCli("convert " + src.string() + " " + out.string() + " --quiet");
    ASSERT_EQ(r.exitCode, 0) << name << ": " << r.err;
    expectSameVoxels(tessera::readVolume(out.string()), original);
  }
}

TEST(ConvertCommand, CropAndDownsampleMatchDirectIndexing) {
  const tessera::test::TempDir tmp;
  const auto out = tmp / "c.nrrd";
  const auto r = runCli("convert gen:shepp-logan:64 " + out.string() +
                        " --crop 8:56,4:60,10:50 --downsample 2x2x1");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("100%"), std::string::npos) << "progress goes to stderr";
  const tessera::Volume full = tessera::makeSheppLogan({64, 64, 64});
  const tessera::Volume v = tessera::readVolume(out.string());
  ASSERT_EQ(v.dims(), glm::ivec3(24, 28, 40));
  for (int z = 0; z < 40; ++z) {
    for (int y = 0; y < 28; ++y) {
      for (int x = 0; x < 24; ++x) {
        double sum = 0;
        for (int dy = 0; dy < 2; ++dy) {
          for (int dx = 0; dx < 2; ++dx)
            sum += full.valueAt(8 + 2 * x + dx, 4 + 2 * y + dy, 10 + z);
        }
        ASSERT_EQ(v.valueAt(x, y, z), std::round(sum / 4)) << x << "," << y << "," << z;
      }
    }
  }
}

TEST(ConvertCommand, FailuresLeaveNoFileBehind) {
  const tessera::test::TempDir tmp;
  for (const std::string& args :
       {"gen:sphere:16 " + (tmp / "x.unknown").string(),
        "gen:sphere:16 " + (tmp / "x.nrrd").string() + " --crop 0:99,0:16,0:16",
        "/nonexistent.nii " + (tmp / "y.nrrd").string(),
        "gen:sphere:16 " + (tmp / "no/such/dir/z.nrrd").string()}) {
    const auto r = runCli("convert " + args);
    EXPECT_NE(r.exitCode, 0) << args;
    EXPECT_NE(r.err.find("tessera: error:"), std::string::npos) << r.err;
  }
  // Nothing under any name: no partial outputs, no temporary files.
  EXPECT_TRUE(fs::is_empty(tmp.path()));
}

// A format that cannot hold the orientation says so, even with --quiet, and
// one that can says nothing.
TEST(ConvertCommand, SaysWhatTheOutputFormatCannotHold) {
  const tessera::test::TempDir tmp;
  tessera::Volume v = tessera::makeSheppLogan({12, 10, 8});
  v.setDirection(glm::dmat3(glm::dvec3(-1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 1)));
  const auto las = tmp / "las.nrrd";
  tessera::writeVolume(v, las);
  const auto pvm = runCli("convert " + las.string() + " " + (tmp / "a.pvm").string() + " --quiet");
  ASSERT_EQ(pvm.exitCode, 0) << pvm.err;
  EXPECT_NE(pvm.out.find(", LAS ("), std::string::npos) << pvm.out;
  EXPECT_NE(pvm.err.find("note: PVM stores spacing only: orientation LAS is lost"),
            std::string::npos)
      << pvm.err;
  const auto nii = runCli("convert " + las.string() + " " + (tmp / "a.nii").string() + " --quiet");
  ASSERT_EQ(nii.exitCode, 0) << nii.err;
  EXPECT_EQ(nii.err.find("note:"), std::string::npos) << nii.err;
}

// f32 into DICOM goes through 16-bit integers: convert says how lossy, and
// the number is the error actually found in the written series.
TEST(ConvertCommand, FloatToDicomSaysItIsLossyAndByHowMuch) {
  const tessera::test::TempDir tmp;
  tessera::Volume v = tessera::Volume::allocate({9, 8, 7}, tessera::ScalarType::F32);
  for (std::size_t i = 0; i < v.voxelCount(); ++i) v.setValueAtIndex(i, std::sin(0.37 * i) * 3.3);
  const auto src = tmp / "f.nii";
  tessera::writeVolume(v, src);
  const auto r = runCli("convert " + src.string() + " " + (tmp / "d/").string() + " --quiet");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto at = r.err.find("max error ");
  ASSERT_NE(at, std::string::npos) << r.err;
  const double claimed = std::stod(r.err.substr(at + 10));
  const tessera::Volume back = tessera::readVolume((tmp / "d").string());
  double worst = 0.0;
  for (std::size_t i = 0; i < v.voxelCount(); ++i) {
    worst = std::max(worst, std::abs(back.valueAtIndex(i) - v.valueAtIndex(i)));
  }
  EXPECT_GT(worst, 0.0);
  EXPECT_NEAR(claimed, worst, 0.01 * worst + 1e-9);
}
