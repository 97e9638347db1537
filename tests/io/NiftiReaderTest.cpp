#include "tessera/io/NiftiReader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "io/IoFixtures.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"

namespace tessera {
namespace {

using test::expectRejected;
using test::NiftiFields;
using test::niftiHeader;
using test::TempDir;
using test::voxelBytes;
using test::writeFile;

constexpr int kDtInt16 = 4;
constexpr int kDtInt32 = 8;
constexpr int kDtFloat32 = 16;
constexpr int kDtComplex64 = 32;
constexpr int kDtFloat64 = 64;
constexpr int kDtRgb24 = 128;
constexpr int kDtInt8 = 256;
constexpr int kDtUint16 = 512;

std::filesystem::path writeNifti(const TempDir& dir, const std::string& name, const NiftiFields& f,
                                 const std::string& voxels, bool gzip = false) {
  const std::string bytes = niftiHeader(f) + voxels;
  const auto path = dir / name;
  writeFile(path, gzip ? test::gzipBytes(bytes) : bytes);
  return path;
}

// Writes `values` as the voxels of a file with header `f` (in its byte
// order), reads it and expects every value back as it was.
template <class T>
Volume readBackValues(const TempDir& dir, const std::string& name, const NiftiFields& f,
                      const std::vector<T>& values, bool gzip = false) {
  const Volume v = readNifti(writeNifti(dir, name, f, voxelBytes(values, f.bigEndian), gzip));
  for (std::size_t i = 0; i < values.size(); ++i) EXPECT_EQ(v.valueAtIndex(i), values[i]) << i;
  return v;
}

std::vector<std::uint8_t> ramp(std::size_t n) {
  std::vector<std::uint8_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint8_t>((i * 37 + 11) % 256);
  return v;
}

TEST(NiftiReader, ReadsUncompressedU8VoxelsDimsAndSpacingExactly) {
  TempDir dir;
  NiftiFields f;
  f.pixdim[1] = 0.5;
  f.pixdim[2] = 1.25;
  f.pixdim[3] = 3.0;
  const auto values = ramp(4 * 3 * 2);
  const Volume v = readBackValues(dir, "a.nii", f, values);
  EXPECT_EQ(v.dims(), glm::ivec3(4, 3, 2));
  EXPECT_EQ(v.type(), ScalarType::U8);
  EXPECT_EQ(v.spacing(), glm::dvec3(0.5, 1.25, 3.0));
  EXPECT_NE(v.description().find("NIfTI-1"), std::string::npos) << v.description();
}

TEST(NiftiReader, ReadsGzipInt16Exactly) {
  TempDir dir;
  NiftiFields f;
  f.dim[1] = 5;
  f.dim[2] = 4;
  f.dim[3] = 3;
  f.datatype = kDtInt16;
  f.bitpix = 16;
  std::vector<std::int16_t> values(60);
  for (std::size_t i = 0; i < values.size(); ++i)
    values[i] = static_cast<std::int16_t>(i * 1000 - 30000);
  const Volume v = readBackValues(dir, "a.nii.gz", f, values, true);
  EXPECT_EQ(v.dims(), glm::ivec3(5, 4, 3));
  EXPECT_EQ(v.type(), ScalarType::I16);
}

TEST(NiftiReader, SwapsBigEndianHeaderAndVoxels) {
  TempDir dir;
  NiftiFields f;
  f.bigEndian = true;
  f.datatype = kDtUint16;
  f.bitpix = 16;
  f.pixdim[1] = 2.0;
  std::vector<std::uint16_t> values(24);
  for (std::size_t i = 0; i < values.size(); ++i)
    values[i] = static_cast<std::uint16_t>(i * 2731 + 1);
  const Volume v = readBackValues(dir, "be.nii", f, values);
  EXPECT_EQ(v.dims(), glm::ivec3(4, 3, 2));
  EXPECT_EQ(v.type(), ScalarType::U16);
  EXPECT_EQ(v.spacing().x, 2.0);
}

TEST(NiftiReader, ReadsNifti2Float32BigAndLittleEndian) {
  for (bool big : {false, true}) {
    TempDir dir;
    NiftiFields f;
    f.version = 2;
    f.bigEndian = big;
    f.datatype = kDtFloat32;
    f.bitpix = 32;
    f.pixdim[3] = 0.7;
    std::vector<float> values(24);
    for (std::size_t i = 0; i < values.size(); ++i)
      values[i] = -3.5f + 0.25f * static_cast<float>(i);
    const Volume v = readBackValues(dir, "n2.nii.gz", f, values, true);
    EXPECT_EQ(v.dims(), glm::ivec3(4, 3, 2));
    EXPECT_EQ(v.type(), ScalarType::F32);
    EXPECT_EQ(v.spacing().z, 0.7);
    EXPECT_NE(v.description().find("NIfTI-2"), std::string::npos) << v.description();
  }
}

// 24 values of T: first, first + step, ...
template <class T>
std::vector<T> arithmetic(double first, double step) {
  std::vector<T> v(24);
  for (std::size_t i = 0; i < v.size(); ++i)
    v[i] = static_cast<T>(first + step * static_cast<double>(i));
  return v;
}

NiftiFields typed(int datatype, int bitpix, bool bigEndian = false) {
  NiftiFields f;
  f.datatype = datatype;
  f.bitpix = bitpix;
  f.bigEndian = bigEndian;
  return f;
}

TEST(NiftiReader, WidensInt8AndConvertsInt32AndFloat64ToF32) {
  TempDir dir;
  EXPECT_EQ(
      readBackValues(dir, "i8.nii", typed(kDtInt8, 8), arithmetic<std::int8_t>(-128, 11)).type(),
      ScalarType::I16);
  EXPECT_EQ(readBackValues(dir, "i32.nii", typed(kDtInt32, 32),
                           arithmetic<std::int32_t>(-1000000, 100000))
                .type(),
            ScalarType::F32);
  const Volume v =
      readBackValues(dir, "f64.nii", typed(kDtFloat64, 64, true), arithmetic<double>(-4.0, 0.5));
  EXPECT_EQ(v.type(), ScalarType::F32);
  EXPECT_NE(v.description().find("converted to f32"), std::string::npos) << v.description();
}

TEST(NiftiReader, AppliesSlopeAndInterceptAsF32) {
  TempDir dir;
  NiftiFields f;
  f.sclSlope = 2.0;
  f.sclInter = -10.0;
  const auto values = ramp(24);
  const Volume v = readNifti(writeNifti(dir, "s.nii", f, voxelBytes(values, false)));
  EXPECT_EQ(v.type(), ScalarType::F32);
  for (std::size_t i = 0; i < values.size(); ++i) {
    EXPECT_EQ(v.valueAtIndex(i), values[i] * 2.0 - 10.0) << i;
  }
}

TEST(NiftiReader, IdentityOrZeroSlopeKeepsTheStoredType) {
  TempDir dir;
  for (double slope : {0.0, 1.0}) {
    NiftiFields f;
    f.sclSlope = slope;
    const auto values = ramp(24);
    const Volume v = readNifti(writeNifti(dir, "id.nii", f, voxelBytes(values, false)));
    EXPECT_EQ(v.type(), ScalarType::U8) << "slope " << slope;
    EXPECT_EQ(v.valueAtIndex(5), values[5]);
  }
}

TEST(NiftiReader, UsesAbsolutePixdimAndQoffsetOrigin) {
  TempDir dir;
  NiftiFields f;
  f.pixdim[0] = -1;  // qfac
  f.pixdim[1] = -0.9;
  f.qformCode = 1;
  f.qoffset[0] = 10;
  f.qoffset[1] = -20.5;
  f.qoffset[2] = 30;
  const Volume v = readNifti(writeNifti(dir, "q.nii", f, voxelBytes(ramp(24), false)));
  EXPECT_FLOAT_EQ(static_cast<float>(v.spacing().x), 0.9f);
  EXPECT_EQ(v.origin(), glm::dvec3(10, -20.5, 30));
}

TEST(NiftiReader, AcceptsFourDimensionsWithOneTimePoint) {
  TempDir dir;
  NiftiFields f;
  f.dim[0] = 5;  // trailing size-1 axes are harmless
  const Volume v = readNifti(writeNifti(dir, "t1.nii", f, voxelBytes(ramp(24), false)));
  EXPECT_EQ(v.dims(), glm::ivec3(4, 3, 2));
}

TEST(NiftiReader, ReadsHdrImgPair) {
  TempDir dir;
  NiftiFields f;
  f.magic = std::string("ni1\0", 4);
  f.voxOffset = 0;
  const auto values = ramp(24);
  writeFile(dir / "pair.hdr", niftiHeader(f));
  writeFile(dir / "pair.img", voxelBytes(values, false));
  const Volume v = readNifti(dir / "pair.hdr");
  EXPECT_EQ(v.dims(), glm::ivec3(4, 3, 2));
  for (std::size_t i = 0; i < values.size(); ++i) EXPECT_EQ(v.valueAtIndex(i), values[i]);
}

TEST(NiftiReader, LoadsTheCh2Template) {
  const std::filesystem::path ch2 = "/usr/share/mricron/templates/ch2.nii.gz";
  if (!std::filesystem::exists(ch2)) GTEST_SKIP() << ch2 << " is not installed (mricron-data)";
  const Volume v = readNifti(ch2);
  EXPECT_EQ(v.dims(), glm::ivec3(181, 217, 181));
  EXPECT_EQ(v.type(), ScalarType::U8);
  EXPECT_EQ(v.spacing(), glm::dvec3(1.0, 1.0, 1.0));
  // A T1 head: a dark background and bright tissue.
  EXPECT_EQ(v.valueAt(0, 0, 0), 0.0);
  EXPECT_GT(v.valueRange().max, 200.0);
  EXPECT_GT(v.valueAt(90, 108, 90), 0.0);
}

// ---- malformed input: each is refused with the file name and the problem ----

TEST(NiftiReaderRejects, TruncatedVoxelData) {
  TempDir dir;
  const std::string data = voxelBytes(ramp(24), false).substr(0, 20);
  const auto path = writeNifti(dir, "short.nii", NiftiFields{}, data);
  expectRejected<InputError>([&] { readNifti(path); },
                             {path.string(), "4x3x2 u8", "at offset 352", "file has"});
}

TEST(NiftiReaderRejects, HeaderDimsFarLargerThanFile) {
  TempDir dir;
  NiftiFields f;
  f.dim[1] = 181;
  f.dim[2] = 217;
  f.dim[3] = 181;
  const auto path = writeNifti(dir, "big.nii", f, std::string(1 << 20, '\0'));
  expectRejected<InputError>(
      [&] { readNifti(path); },
      {path.string(), "header says 181x217x181 u8 = ", "of voxel data at offset 352", "file has 1",
       "needs 7109489 bytes, has 1048928"});
}

TEST(NiftiReaderRejects, MaximalNifti1DimsWithoutData) {
  TempDir dir;
  NiftiFields f;
  f.dim[1] = f.dim[2] = f.dim[3] = 32767;
  const auto path = writeNifti(dir, "max.nii", f, "");
  expectRejected<InputError>([&] { readNifti(path); }, {path.string(), "32767x32767x32767"});
}

TEST(NiftiReaderRejects, ZeroAndNegativeDims) {
  TempDir dir;
  for (int bad : {0, -5}) {
    NiftiFields f;
    f.dim[2] = bad;
    const auto path = writeNifti(dir, "zero.nii", f, voxelBytes(ramp(24), false));
    expectRejected<InputError>([&] { readNifti(path); },
                               {path.string(), "dim[2] is " + std::to_string(bad)});
  }
}

TEST(NiftiReaderRejects, Nifti2DimsNear2To31) {
  TempDir dir;
  NiftiFields f;
  f.version = 2;
  f.dim[1] = 2147483647;
  f.dim[2] = 2147483647;
  const auto path = writeNifti(dir, "huge.nii", f, "");
  expectRejected<InputError>([&] { readNifti(path); }, {path.string(), "dim[1] is 2147483647"});
}

TEST(NiftiReaderRejects, WrongDimensionality) {
  TempDir dir;
  {
    NiftiFields f;
    f.dim[0] = 2;
    const auto path = writeNifti(dir, "2d.nii", f, voxelBytes(ramp(24), false));
    expectRejected<InputError>([&] { readNifti(path); }, {path.string(), "dim[0] is 2"});
  }
  {
    NiftiFields f;
    f.dim[0] = 5;
    f.dim[5] = 3;  // three vector components per voxel
    const auto path = writeNifti(dir, "5d.nii", f, voxelBytes(ramp(72), false));
    expectRejected<InputError>([&] { readNifti(path); }, {path.string(), "dim[5] is 3"});
  }
  {
    // 10 time points declared, the data for 6: refused whichever is asked.
    NiftiFields f;
    f.dim[0] = 4;
    f.dim[4] = 10;
    const auto path = writeNifti(dir, "short4d.nii", f, voxelBytes(ramp(144), false));
    for (const int t : {0, 5, 6}) {
      expectRejected<InputError>(
          [&] { readNifti(path, t); },
          {path.string(), "header says 10 time points of 24 B", "holds 6 complete ones"});
    }
  }
}

// A 4-D file (4x3x2 voxels, 10 time points, the ramp running through all of
// them): time point t is the t-th block of 24 voxels, i fastest.
TEST(NiftiReader, TimePointsOfA4DFileAreConsecutiveVolumes) {
  TempDir dir;
  NiftiFields f;
  f.dim[0] = 4;
  f.dim[4] = 10;
  const auto values = ramp(240);
  const auto path = writeNifti(dir, "4d.nii", f, voxelBytes(values, false));
  EXPECT_EQ(niftiTimePoints(FileSource(path)), 10);
  for (const int t : {0, 3, 9}) {
    const Volume v = readNifti(path, t);
    ASSERT_EQ(v.dims(), glm::ivec3(4, 3, 2));
    for (int k = 0; k < 2; ++k) {
      for (int j = 0; j < 3; ++j) {
        for (int i = 0; i < 4; ++i) {
          ASSERT_EQ(v.valueAt(i, j, k),
                    values[static_cast<std::size_t>(t * 24 + i + 4 * (j + 3 * k))])
              << "t " << t << " voxel " << i << "," << j << "," << k;
        }
      }
    }
  }
  expectRejected<InputError>([&] { readNifti(path, 10); },
                             {path.string(), "time point 10 asked for, but the file holds 10"});
  expectRejected<InputError>([&] { readNifti(path, -1); }, {path.string(), "time point -1"});
}

TEST(NiftiReaderRejects, NanAndZeroVoxelSize) {
  TempDir dir;
  for (double bad :
       {std::numeric_limits<double>::quiet_NaN(), 0.0, std::numeric_limits<double>::infinity()}) {
    NiftiFields f;
    f.pixdim[1] = bad;
    const auto path = writeNifti(dir, "px.nii", f, voxelBytes(ramp(24), false));
    expectRejected<InputError>([&] { readNifti(path); }, {path.string(), "pixdim[1] is"});
  }
}

TEST(NiftiReaderRejects, UnsupportedDatatypesByName) {
  TempDir dir;
  const std::pair<int, std::string> cases[] = {
      {kDtComplex64, "COMPLEX64"}, {kDtRgb24, "RGB24"}, {999, "not a NIfTI datatype"}};
  for (const auto& [dt, name] : cases) {
    NiftiFields f;
    f.datatype = dt;
    const auto path = writeNifti(dir, "dt.nii", f, std::string(24 * 8, '\0'));
    expectRejected<InputError>([&] { readNifti(path); }, {path.string(), name, "not supported"});
  }
}

TEST(NiftiReaderRejects, WrongMagicAndHeaderSize) {
  TempDir dir;
  {
    NiftiFields f;
    f.magic = std::string("xyz\0", 4);
    const auto path = writeNifti(dir, "magic.nii", f, voxelBytes(ramp(24), false));
    expectRejected<InputError>([&] { readNifti(path); }, {path.string(), "magic is 'xyz'"});
  }
  {
    NiftiFields f;
    f.sizeofHdr = 123;
    const auto path = writeNifti(dir, "size.nii", f, voxelBytes(ramp(24), false));
    expectRejected<InputError>([&] { readNifti(path); }, {path.string(), "sizeof_hdr is 123"});
  }
  {
    const auto path = dir / "tiny.nii";
    writeFile(path, "abc");
    expectRejected<InputError>([&] { readNifti(path); }, {path.string(), "too short"});
  }
  {
    const auto path = dir / "text.nii";
    writeFile(path, std::string(400, 'x'));
    expectRejected<InputError>([&] { readNifti(path); }, {path.string(), "not a NIfTI file"});
  }
}

TEST(NiftiReaderRejects, VoxOffsetBeyondFile) {
  TempDir dir;
  NiftiFields f;
  f.voxOffset = 1e9;
  const auto path = writeNifti(dir, "off.nii", f, voxelBytes(ramp(24), false));
  expectRejected<InputError>([&] { readNifti(path); }, {path.string(), "vox_offset"});
}

TEST(NiftiReaderRejects, TruncatedGzipStream) {
  TempDir dir;
  NiftiFields f;
  f.dim[1] = 64;
  f.dim[2] = 64;
  f.dim[3] = 64;
  const std::string voxels = test::noiseBytes(64 * 64 * 64);
  const std::string gz = test::gzipBytes(niftiHeader(f) + voxels);
  const auto path = dir / "cut.nii.gz";
  writeFile(path, gz.substr(0, gz.size() / 2));
  expectRejected<InputError>([&] { readNifti(path); },
                             {path.string(), "gzip data ends after", "of 262144 bytes"});
}

TEST(NiftiReaderRejects, GzipBombOverTheHostBudgetWithoutAllocating) {
  TempDir dir;
  NiftiFields f;
  f.dim[1] = f.dim[2] = f.dim[3] = 1000;  // 1 GB claimed, a few KiB stored
  const auto path = writeNifti(dir, "bomb.nii.gz", f, std::string(4096, '\0'), true);
  test::BudgetOverride budget(64ull << 20);
  expectRejected<BudgetError>([&] { readNifti(path); }, {path.string(), "budget"});
}

TEST(NiftiReaderRejects, GzipClaimBeyondWhatDeflateCanHold) {
  TempDir dir;
  NiftiFields f;
  f.dim[1] = f.dim[2] = f.dim[3] = 512;  // 128 MiB claimed: within budget, but not in 1 KiB
  const auto path = writeNifti(dir, "liar.nii.gz", f, std::string(4096, '\0'), true);
  test::BudgetOverride budget(4ull << 30);
  expectRejected<InputError>([&] { readNifti(path); }, {path.string(), "can inflate to at most"});
}

TEST(NiftiReaderRejects, MissingFileAndDirectory) {
  TempDir dir;
  expectRejected<InputError>([&] { readNifti(dir / "nope.nii"); }, {"nope.nii", "no such file"});
  expectRejected<InputError>([&] { readNifti(dir.path()); },
                             {dir.path().string(), "is a directory"});
}

}  // namespace
}  // namespace tessera
