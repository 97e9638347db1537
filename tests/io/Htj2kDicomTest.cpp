// DICOM series in HTJ2K (.201, .202, .203), decoded natively by OpenJPH
// (io/Htj2kFrame.h) and read through readVolume like any DICOM folder:
// lossless streams give the uncompressed original's voxels exactly at 8, 12
// and 16 bits, signed and unsigned; lossy ones stay above a PSNR floor; a
// corrupt, truncated or mis-declared frame is one line naming the file.
// The series are synthetic phantoms encoded here by Debian's ojph_compress
// and wrapped by pydicom (tests/io/Htj2kSeries.py).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "support/ExpectError.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/VolumeReader.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

const fs::path kSeries = fs::path(TESSERA_TEST_DATA_DIR) / ".." / "io" / "Htj2kSeries.py";

bool have(const std::string& command) {
  return std::system((command + " >/dev/null 2>&1").c_str()) == 0;
}

std::string missing() {
  if (!have("/usr/bin/python3 -c 'import pydicom, numpy'")) return "needs python3-pydicom, numpy";
  if (!have("command -v ojph_compress")) return "needs ojph_compress (openjph-tools)";
  return "";
}

// Writes the cases' folders under `dir` (one python run for all of them).
void make(const fs::path& dir, const std::vector<std::string>& cases) {
  std::string cmd = "/usr/bin/python3 '" + kSeries.string() + "' '" + dir.string() + "'";
  for (const auto& c : cases) cmd += " " + c;
  ASSERT_TRUE(have(cmd)) << cmd;
}

double psnr(const Volume& a, const Volume& b, int bits) {
  double squared = 0.0;
  for (std::size_t i = 0; i < a.voxelCount(); ++i) {
    const double d = a.valueAtIndex(i) - b.valueAtIndex(i);
    squared += d * d;
  }
  const double peak = std::ldexp(1.0, bits) - 1.0;
  const double mse = squared / static_cast<double>(a.voxelCount());
  return mse == 0.0 ? INFINITY : 10.0 * std::log10(peak * peak / mse);
}

std::size_t differing(const Volume& a, const Volume& b) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.voxelCount(); ++i) n += a.valueAtIndex(i) != b.valueAtIndex(i);
  return n;
}

TEST(Htj2kDicom, LosslessEqualsTheUncompressedOriginalAt8To16BitsSignedAndUnsigned) {
  if (const std::string m = missing(); !m.empty()) GTEST_SKIP() << m;
  test::TempDir dir;
  const std::vector<std::string> cases = {
      "lossless-8-u",  "lossless-8-s",  "lossless-12-u", "lossless-12-s",
      "lossless-16-u", "lossless-16-s", "rpcl-12-s",     "rpcl-16-u",
      "in-j2k-16-s",  // an HTJ2K stream in a file that says JPEG 2000 (.90)
  };
  make(dir.path(), cases);
  for (const auto& c : cases) {
    SCOPED_TRACE(c);
    const Volume plain = readVolume((dir.path() / c / "plain").string());
    const Volume coded = readVolume((dir.path() / c / "coded").string());
    ASSERT_EQ(coded.dims(), plain.dims());
    ASSERT_EQ(coded.dims(), glm::ivec3(48, 40, 3));
    EXPECT_EQ(coded.type(), plain.type());
    EXPECT_EQ(differing(coded, plain), 0u) << "of " << plain.voxelCount();
    EXPECT_EQ(coded.indexToWorld(), plain.indexToWorld());
    EXPECT_NE(coded.description().find(c.starts_with("in-j2k") ? "1.2.840.10008.1.2.4.90"
                                       : c.starts_with("rpcl") ? "1.2.840.10008.1.2.4.202"
                                                               : "1.2.840.10008.1.2.4.201"),
              std::string::npos)
        << coded.description();
  }
}

// The 9/7 wavelet at ojph_compress's -qstep 0.0005: measured 12-bit
// unsigned 74.4 dB, 16-bit signed 75.2 dB (8-bit comes back exact at that
// step); the floor is 45 dB. OpenJPEG's decode of the 12-bit stream: 74.4 dB.
TEST(Htj2kDicom, LossyStaysAboveAPsnrFloor) {
  if (const std::string m = missing(); !m.empty()) GTEST_SKIP() << m;
  test::TempDir dir;
  const std::vector<std::pair<std::string, int>> cases = {
      {"lossy-8-u", 8}, {"lossy-12-u", 12}, {"lossy-16-s", 16}};
  std::vector<std::string> names;
  for (const auto& c : cases) names.push_back(c.first);
  make(dir.path(), names);
  for (const auto& [c, bits] : cases) {
    SCOPED_TRACE(c);
    const Volume plain = readVolume((dir.path() / c / "plain").string());
    const Volume coded = readVolume((dir.path() / c / "coded").string());
    ASSERT_EQ(coded.dims(), plain.dims());
    const double db = psnr(coded, plain, bits);
    std::printf("[ htj2k ] %s: PSNR %.1f dB, %zu of %zu voxels differ\n", c.c_str(), db,
                differing(coded, plain), plain.voxelCount());
    EXPECT_GT(db, 45.0);
    EXPECT_NE(coded.description().find("1.2.840.10008.1.2.4.203"), std::string::npos);
  }
}

// Each: one line that starts with the slice's file and says what is wrong.
TEST(Htj2kDicom, CorruptTruncatedOrMisDeclaredFramesAreNamedErrors) {
  if (const std::string m = missing(); !m.empty()) GTEST_SKIP() << m;
  test::TempDir dir;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"lossless-16-s-truncated", "truncated?"},
      {"lossless-12-u-cut90", "truncated?"},
      {"lossless-16-s-rows", "the HTJ2K frame is 48x40 pixels, but the file declares 48x20"},
      {"lossless-16-s-garbage", "no SOC marker: not a JPEG 2000 codestream"},
      {"lossless-16-u-nosoc", "no SOC marker: not a JPEG 2000 codestream"},
      {"lossless-16-u-sign",
       "the HTJ2K frame holds unsigned samples, but the file declares Pixel Representation 1"},
      {"lossless-8-u-colour", "a HTJ2K frame of 3 components; only greyscale"},
      // OpenJPH 0.9 decodes 2-D tilings wrongly (its ojph_expand too; OpenJPEG
      // decodes the same stream exactly): refused rather than read wrong.
      {"rpcl-16-u-tiles", "a tiled HTJ2K frame (tile 1) is not read"},
  };
  std::vector<std::string> names;
  for (const auto& c : cases) names.push_back(c.first);
  make(dir.path(), names);
  for (const auto& [c, expected] : cases) {
    SCOPED_TRACE(c);
    const fs::path coded = dir.path() / c / "coded";
    const std::string message = test::inputErrorMessage([&] { readVolume(coded.string()); });
    EXPECT_EQ(message.rfind((coded / "slice").string(), 0), 0u) << message;
    EXPECT_NE(message.find(".dcm: "), std::string::npos) << message;
    EXPECT_NE(message.find(expected), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace tessera
