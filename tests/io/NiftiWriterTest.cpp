#include "tessera/io/NiftiWriter.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "io/IoFixtures.h"
#include "tessera/core/Error.h"
#include "tessera/io/NiftiReader.h"

namespace tessera {
namespace {

// The io fixtures are this suite's vocabulary.
using namespace test;

// NIfTI-1 stores spacing and origin as float: these are exact in float.
const test::RandomVolumeOptions kPlaced{.spacing = {0.5, 1.25, 3.0}, .origin = {-90.5, 12.25, 7.0}};

constexpr ScalarType kAllTypes[] = {ScalarType::U8, ScalarType::U16, ScalarType::I16,
                                    ScalarType::F32};

template <class T>
T at(const std::string& bytes, std::size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof v);
  return v;
}

int entriesIn(const std::filesystem::path& dir) {
  int n = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++n;
  return n;
}

TEST(NiftiWriter, RoundTripsEveryTypeExactlyThroughNiiAndNiiGz) {
  TempDir dir;
  for (const char* name : {"v.nii", "v.nii.gz"}) {
    for (ScalarType type : kAllTypes) {
      SCOPED_TRACE(std::string(name) + " " + std::string(scalarTypeName(type)));
      const Volume v = randomVolume({7, 5, 3}, type, 1, kPlaced);
      writeNifti(v, dir / name);
      expectSameVolume(readNifti(dir / name), v);
    }
  }
}

TEST(NiftiWriter, WritesANifti1HeaderWithSformQformAndNoScaling) {
  TempDir dir;
  const Volume v = randomVolume({7, 5, 3}, ScalarType::I16, 2, kPlaced);
  writeNifti(v, dir / "h.nii");
  const std::string b = fileBytes(dir / "h.nii");
  // Offsets from nifti1.h.
  ASSERT_EQ(b.size(), 352u + v.byteSize());
  EXPECT_EQ(at<std::int32_t>(b, 0), 348);
  EXPECT_EQ(b.substr(344, 4), std::string("n+1\0", 4));
  EXPECT_EQ(at<std::int16_t>(b, 40), 3);
  EXPECT_EQ(at<std::int16_t>(b, 42), 7);
  EXPECT_EQ(at<std::int16_t>(b, 44), 5);
  EXPECT_EQ(at<std::int16_t>(b, 46), 3);
  EXPECT_EQ(at<std::int16_t>(b, 70), 4);   // DT_INT16
  EXPECT_EQ(at<std::int16_t>(b, 72), 16);  // bitpix
  EXPECT_EQ(at<float>(b, 76), 1.0f);       // qfac
  EXPECT_EQ(at<float>(b, 80), 0.5f);
  EXPECT_EQ(at<float>(b, 84), 1.25f);
  EXPECT_EQ(at<float>(b, 88), 3.0f);
  EXPECT_EQ(at<float>(b, 108), 352.0f);    // vox_offset
  EXPECT_EQ(at<float>(b, 112), 0.0f);      // scl_slope: no scaling
  EXPECT_EQ(at<std::int16_t>(b, 252), 1);  // qform_code: scanner
  EXPECT_EQ(at<std::int16_t>(b, 254), 1);  // sform_code: scanner
  for (std::size_t q = 256; q < 268; q += 4) EXPECT_EQ(at<float>(b, q), 0.0f);  // identity
  EXPECT_EQ(at<float>(b, 268), -90.5f);
  EXPECT_EQ(at<float>(b, 272), 12.25f);
  EXPECT_EQ(at<float>(b, 276), 7.0f);
  // srow_x, srow_y, srow_z: diag(spacing) and the origin.
  const float srow[3][4] = {{0.5f, 0, 0, -90.5f}, {0, 1.25f, 0, 12.25f}, {0, 0, 3.0f, 7.0f}};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) EXPECT_EQ(at<float>(b, 280 + 16 * r + 4 * c), srow[r][c]);
  }
  EXPECT_EQ(std::memcmp(b.data() + 352, v.bytes().data(), v.byteSize()), 0);
}

TEST(NiftiWriter, NiiGzIsGzipCompressed) {
  TempDir dir;
  Volume v = Volume::allocate({32, 32, 32}, ScalarType::U8);  // zeros compress well
  writeNifti(v, dir / "z.nii.gz");
  const std::string b = fileBytes(dir / "z.nii.gz");
  EXPECT_EQ(b.substr(0, 2), "\x1f\x8b");
  EXPECT_LT(b.size(), v.byteSize() / 10);
}

TEST(NiftiWriter, Ch2RoundTripsExactly) {
  expectCh2RoundTrips(
      {"ch2.nii", "ch2.nii.gz"}, [](const Volume& v, const auto& path) { writeNifti(v, path); },
      [](const auto& path) { return readNifti(path); });
}

TEST(NiftiWriter, ReplacingAFileLeavesNoTemporaryBehind) {
  TempDir dir;
  test::writeFile(dir / "a.nii.gz", "old contents");
  const Volume v = randomVolume({4, 4, 4}, ScalarType::F32, 3, kPlaced);
  writeNifti(v, dir / "a.nii.gz");
  expectSameVolume(readNifti(dir / "a.nii.gz"), v);
  EXPECT_EQ(entriesIn(dir.path()), 1);
}

TEST(NiftiWriter, WritingIntoAMissingDirectoryFailsNamingThePathAndLeavesNothing) {
  TempDir dir;
  expectWriteIntoMissingFolderFails(dir, dir / "no" / "such" / "dir" / "x.nii",
                                    [](const Volume& v, const auto& path) { writeNifti(v, path); });
}

TEST(NiftiWriter, AFailedRenameRemovesTheTemporaryFile) {
  TempDir dir;
  // A directory under the target name: the data are written, the rename fails.
  std::filesystem::create_directory(dir / "taken.nii");
  expectRejected<Error>(
      [&] {
        writeNifti(randomVolume({2, 2, 2}, ScalarType::U8, 1, kPlaced), dir / "taken.nii");
      },
      {(dir / "taken.nii").string(), "rename"});
  EXPECT_EQ(entriesIn(dir.path()), 1);
  EXPECT_TRUE(std::filesystem::is_directory(dir / "taken.nii"));
}

TEST(NiftiWriter, RefusesNamesThatAreNotNiiOrNiiGz) {
  TempDir dir;
  const Volume v = randomVolume({2, 2, 2}, ScalarType::U8, 1, kPlaced);
  for (const char* name : {"x.hdr", "x.img", "x.nii.bz2", "x"}) {
    expectRejected<InputError>([&] { writeNifti(v, dir / name); },
                               {(dir / name).string(), ".nii or .nii.gz"});
  }
  EXPECT_EQ(entriesIn(dir.path()), 0);
}

TEST(NiftiWriter, RefusesDimsBeyondNifti1sInt16) {
  TempDir dir;
  const Volume v = Volume::allocate({32768, 1, 1}, ScalarType::U8);
  expectRejected<InputError>([&] { writeNifti(v, dir / "wide.nii"); },
                             {"wide.nii", "32768x1x1", "32767"});
  EXPECT_EQ(entriesIn(dir.path()), 0);
}

}  // namespace
}  // namespace tessera
