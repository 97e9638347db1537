// The DICOM reader without DCMTK (io/DicomBasicReader.h) against the DCMTK
// reader: the same volume, voxel for voxel, and the same affine, bit for bit,
// on series our writer makes (explicit VR, implicit VR, RLE by DCMTK), on
// pydicom's RLE encoding and on ch2; then malformed input, which must be an
// InputError naming the file, never a crash, a hang or a large allocation.
#include "tessera/io/DicomBasicReader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <dcmtk/config/osconfig.h>
#include <dcmtk/dcmdata/dcdatset.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcxfer.h>

#include "io/IoFixtures.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/io/ByteSource.h"
#include "tessera/io/DicomDecoder.h"
#include "tessera/io/DicomSeriesReader.h"
#include "tessera/io/NiftiReader.h"
#include "tessera/io/VolumeReader.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

void expectSameVolume(const Volume& basic, const Volume& dcmtk) {
  ASSERT_EQ(basic.dims(), dcmtk.dims());
  EXPECT_EQ(basic.type(), dcmtk.type());
  // Exact: both run the same geometry code on the same numbers.
  EXPECT_EQ(basic.spacing(), dcmtk.spacing());
  EXPECT_EQ(basic.origin(), dcmtk.origin());
  EXPECT_EQ(basic.direction(), dcmtk.direction());
  EXPECT_EQ(basic.geometrySource(), dcmtk.geometrySource());
  EXPECT_EQ(basic.description(), dcmtk.description());
  ASSERT_EQ(basic.byteSize(), dcmtk.byteSize());
  EXPECT_EQ(std::memcmp(basic.bytes().data(), dcmtk.bytes().data(), basic.byteSize()), 0)
      << "voxels differ";
}

std::vector<fs::path> filesIn(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

// Rewrites every file of `dir` in `xfer` through DCMTK.
void transcode(const fs::path& dir, E_TransferSyntax xfer) {
  for (const auto& f : filesIn(dir)) {
    DcmFileFormat ff;
    ASSERT_TRUE(ff.loadFile(f.c_str()).good());
    ASSERT_TRUE(ff.loadAllDataIntoMemory().good());
    const OFCondition c = ff.saveFile(f.c_str(), xfer, EET_ExplicitLength);
    ASSERT_TRUE(c.good()) << c.text();
  }
}

std::string readBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A volume of noise with an oblique, left-handed affine: any swapped axis,
// flipped sign or misplaced slice shows.
Volume noiseVolume(ScalarType type, unsigned seed) {
  Volume v = Volume::allocate({13, 11, 5}, type);
  if (type == ScalarType::F32) {
    for (std::size_t i = 0; i < v.voxelCount(); ++i) {
      v.setValueAtIndex(i, -3.25 + 0.37 * static_cast<double>((i * 7919) % 101));
    }
  } else {
    const std::string noise = test::noiseBytes(v.byteSize(), seed);
    std::memcpy(v.bytes().data(), noise.data(), noise.size());
  }
  v.invalidateRange();
  v.setSpacing({0.7, 0.9, 2.5});
  const double c = std::cos(0.3);
  const double s = std::sin(0.3);
  // Rotated about z, third axis flipped: left-handed.
  v.setDirection(glm::dmat3(glm::dvec3(c, s, 0), glm::dvec3(-s, c, 0), glm::dvec3(0, 0, -1)));
  v.setOrigin({-12.5, 40.25, 7.0});
  return v;
}

TEST(DicomBasicReader, EqualsDcmtkVoxelAndGeometryExactOnWrittenSeries) {
  struct Encoding {
    const char* name;
    const char* writerSyntax;
    E_TransferSyntax transcodeTo;  // EXS_Unknown: as written
  };
  const Encoding encodings[] = {
      {"explicit VR little endian", "little-endian-explicit", EXS_Unknown},
      {"implicit VR little endian", "little-endian-explicit", EXS_LittleEndianImplicit},
      {"RLE lossless (DCMTK)", "rle", EXS_Unknown},
  };
  unsigned seed = 3;
  for (const Encoding& enc : encodings) {
    for (ScalarType type : {ScalarType::U8, ScalarType::U16, ScalarType::I16, ScalarType::F32}) {
      SCOPED_TRACE(std::string(enc.name) + " " + std::string(scalarTypeName(type)));
      test::TempDir dir;
      const Volume v = noiseVolume(type, ++seed);
      DicomWriteOptions o;
      o.transferSyntax = enc.writerSyntax;
      o.shuffleFileNames = true;
      if (type == ScalarType::I16) {
        o.rescaleSlope = 1;
        o.rescaleIntercept = -1024;  // stored = value + 1024 must fit i16
        Volume shifted = Volume::allocate(v.dims(), type);
        for (std::size_t i = 0; i < v.voxelCount(); ++i) {
          shifted.setValueAtIndex(i, std::clamp(v.valueAtIndex(i), -31000.0, 31000.0));
        }
        shifted.invalidateRange();
        shifted.setSpacing(v.spacing());
        shifted.setDirection(v.direction());
        shifted.setOrigin(v.origin());
        writeDicomSeries(shifted, dir.path(), o);
      } else {
        writeDicomSeries(v, dir.path(), o);
      }
      if (enc.transcodeTo != EXS_Unknown) transcode(dir.path(), enc.transcodeTo);
      const Volume dcmtk = readDicomSeries(dir.path());
      const Volume basic = readDicomSeriesBasic(dir.path());
      expectSameVolume(basic, dcmtk);
      // One file names its series, read from the files beside it.
      const fs::path one = filesIn(dir.path())[2];
      expectSameVolume(readDicomSeriesBasic(one), readDicomSeries(one));
    }
  }
}

TEST(DicomBasicReader, EqualsDcmtkOnCh2ExplicitAndRle) {
  const fs::path ch2 = "/usr/share/mricron/templates/ch2.nii.gz";
  if (!fs::exists(ch2)) GTEST_SKIP() << ch2 << " not installed";
  const Volume nifti = readNifti(ch2);
  for (const char* syntax : {"little-endian-explicit", "rle"}) {
    SCOPED_TRACE(syntax);
    test::TempDir dir;
    DicomWriteOptions o;
    o.transferSyntax = syntax;
    writeDicomSeries(nifti, dir / "ch2", o);
    const Volume basic = readDicomSeriesBasic(dir / "ch2");
    expectSameVolume(basic, readDicomSeries(dir / "ch2"));
    ASSERT_EQ(basic.byteSize(), nifti.byteSize());
    EXPECT_EQ(std::memcmp(basic.bytes().data(), nifti.bytes().data(), basic.byteSize()), 0);
    // The NIfTI's own affine back (both readers share the LPS -> RAS step).
    for (int c = 0; c < 3; ++c) {
      for (int r = 0; r < 3; ++r) {
        EXPECT_NEAR(basic.direction()[c][r], nifti.direction()[c][r], 1e-9);
      }
      EXPECT_NEAR(basic.origin()[c], nifti.origin()[c], 1e-6);
      EXPECT_NEAR(basic.spacing()[c], nifti.spacing()[c], 1e-9);
    }
  }
}

// pydicom's own RLE encoder (not DCMTK's): 8-bit and signed 16-bit slices
// with runs and literals of every length, oblique positions.
TEST(DicomBasicReader, EqualsDcmtkOnPydicomRleSeries) {
  const std::string python = "/usr/bin/python3";
  if (std::system((python + " -c 'import pydicom, numpy' >/dev/null 2>&1").c_str()) != 0) {
    GTEST_SKIP() << python << " has no pydicom/numpy (apt install python3-pydicom)";
  }
  test::TempDir work;
  test::writeFile(work / "rle.py", R"py(
import sys
import numpy as np
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.uid import ExplicitVRLittleEndian, RLELossless, generate_uid

out, bits = sys.argv[1], int(sys.argv[2])
rng = np.random.default_rng(bits)
series = generate_uid()
for k in range(4):
    d = Dataset()
    d.file_meta = FileMetaDataset()
    d.file_meta.MediaStorageSOPClassUID = '1.2.840.10008.5.1.4.1.1.4'
    d.file_meta.MediaStorageSOPInstanceUID = generate_uid()
    d.file_meta.TransferSyntaxUID = ExplicitVRLittleEndian
    d.is_little_endian, d.is_implicit_VR = True, False
    d.SOPClassUID = d.file_meta.MediaStorageSOPClassUID
    d.SOPInstanceUID = d.file_meta.MediaStorageSOPInstanceUID
    d.SeriesInstanceUID, d.Modality, d.InstanceNumber = series, 'MR', k + 1
    d.ImageOrientationPatient = [0.8, 0.6, 0, -0.6, 0.8, 0]
    d.ImagePositionPatient = [10.5 + 0.1 * k, -20.0, 30.0 + 1.5 * k]
    d.PixelSpacing = [0.75, 0.5]
    d.Rows, d.Columns, d.SamplesPerPixel = 37, 29, 1
    d.PhotometricInterpretation = 'MONOCHROME2'
    d.BitsAllocated = d.BitsStored = bits
    d.HighBit = bits - 1
    signed = bits == 16
    d.PixelRepresentation = 1 if signed else 0
    dtype = np.int16 if signed else np.uint8
    a = rng.integers(-3000 if signed else 0, 3000 if signed else 256, (37, 29)).astype(dtype)
    a[3:9, :] = a[3, 0]          # long replicate runs, longer than 128
    a[20, 5:25] = 7
    d.PixelData = a.tobytes()
    d.compress(RLELossless)
    d.save_as('%s/im%d.dcm' % (out, k), write_like_original=False)
)py");
  for (int bits : {8, 16}) {
    SCOPED_TRACE(bits);
    test::TempDir dir;
    const std::string cmd = python + " " + (work / "rle.py").string() + " " + dir.path().string() +
                            " " + std::to_string(bits);
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    const Volume basic = readDicomSeriesBasic(dir.path());
    EXPECT_NE(basic.description().find("RLE Lossless (1.2.840.10008.1.2.5)"), std::string::npos)
        << basic.description();
    expectSameVolume(basic, readDicomSeries(dir.path()));
  }
}

// What the web page does: the files of a dropped folder in memory (named by
// their path in the folder, one of them not DICOM), read through the
// byte-source entry point.
TEST(DicomBasicReader, DroppedFilesInMemoryGiveTheFolderVolume) {
  test::TempDir dir;
  const Volume v = noiseVolume(ScalarType::U16, 21);
  DicomWriteOptions o;
  o.shuffleFileNames = true;
  writeDicomSeries(v, dir / "series", o);
  MemoryFiles files;
  files.add("series/README.txt", std::vector<std::byte>(40, std::byte{'x'}));
  for (const auto& f : filesIn(dir / "series")) {
    const std::string b = readBytes(f);
    std::vector<std::byte> bytes(b.size());
    std::memcpy(bytes.data(), b.data(), b.size());
    files.add("series/" + f.filename().string(), std::move(bytes));
  }
  const std::string first = files.names()[1];
  const Volume fromMemory = readVolume(*files.open(first), files);
  const Volume fromDisk = readDicomSeries(dir / "series");
  EXPECT_EQ(fromMemory.origin(), fromDisk.origin());
  EXPECT_EQ(fromMemory.direction(), fromDisk.direction());
  EXPECT_EQ(fromMemory.spacing(), fromDisk.spacing());
  ASSERT_EQ(fromMemory.byteSize(), fromDisk.byteSize());
  EXPECT_EQ(std::memcmp(fromMemory.bytes().data(), fromDisk.bytes().data(), v.byteSize()), 0);
  EXPECT_NE(fromMemory.description().find("skipped 1 non-DICOM file(s)"), std::string::npos)
      << fromMemory.description();
}

// pydicom's own test files (python3-pydicom), one at a time: whatever this
// reader reads, DCMTK reads the same; whatever it refuses is an InputError
// naming the file; the uncompressed, RLE and JPEG 2000 greyscale images are
// read.
TEST(DicomBasicReader, PydicomTestFilesReadAsDcmtkDoesOrAreRefusedNamingTheFile) {
  const fs::path dir = "/usr/lib/python3/dist-packages/pydicom/data/test_files";
  if (!fs::is_directory(dir)) GTEST_SKIP() << dir << " missing (apt install python3-pydicom)";
  std::vector<std::string> read;
  for (const auto& f : filesIn(dir)) {
    if (f.extension() != ".dcm") continue;
    SCOPED_TRACE(f.filename().string());
    try {
      const Volume basic = readDicomFilesBasic({f});
      read.push_back(f.filename().string());
      // JPEG 2000 and HTJ2K are this reader's alone (free DCMTK has no
      // codec for them): Jpeg2000DicomTest checks those against the
      // uncompressed originals and OpenJPEG's own decoder.
      if (!dcmtkDicomDecoder().canDecode(dicomTransferSyntaxOf(FileSource(f)))) continue;
      try {
        expectSameVolume(basic, readDicomFiles({f}));
      } catch (const Error& e) {
        ADD_FAILURE() << "read here, but DCMTK says: " << e.what();
      }
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(f.string(), 0), 0u) << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not an InputError: " << e.what();
    }
  }
  for (const char* name :
       {"CT_small.dcm", "MR_small.dcm", "MR_small_RLE.dcm", "MR_small_implicit.dcm",
        "MR_small_jp2klossless.dcm", "JPEG2000.dcm", "693_J2KI.dcm"}) {
    EXPECT_NE(std::find(read.begin(), read.end(), name), read.end()) << name << " not read";
  }
  std::string list;
  for (const auto& n : read) list += " " + n;
  std::printf("read %zu pydicom test files:%s\n", read.size(), list.c_str());
}

// ---- malformed input --------------------------------------------------------

// Reads `bytes` as the only file of a dropped set.
Volume readAlone(const std::string& name, const std::string& bytes) {
  MemoryFiles files;
  std::vector<std::byte> b(bytes.size());
  if (!bytes.empty()) std::memcpy(b.data(), bytes.data(), bytes.size());  // the empty prefix too
  files.add(name, std::move(b));
  return readDicomSeriesBasic(*files.open(name), files);
}

void expectInputError(const std::string& name, const std::string& bytes,
                      const std::vector<std::string>& fragments) {
  std::vector<std::string> all = {name + ": "};
  all.insert(all.end(), fragments.begin(), fragments.end());
  test::expectRejected<InputError>([&] { readAlone(name, bytes); }, all);
}

// One slice file of a small series in `syntax`.
std::string oneSlice(const char* syntax, ScalarType type = ScalarType::U16) {
  test::TempDir dir;
  Volume v = noiseVolume(type, 5);
  DicomWriteOptions o;
  o.transferSyntax = syntax;
  writeDicomSeries(v, dir.path(), o);
  return readBytes(filesIn(dir.path())[0]);
}

std::string implicitSlice() {
  test::TempDir dir;
  writeDicomSeries(noiseVolume(ScalarType::U16, 5), dir.path());
  transcode(dir.path(), EXS_LittleEndianImplicit);
  return readBytes(filesIn(dir.path())[0]);
}

TEST(DicomBasicReader, EveryTruncationIsAnInputErrorNamingTheFile) {
  for (const std::string& file :
       {oneSlice("little-endian-explicit"), implicitSlice(), oneSlice("rle")}) {
    ASSERT_NO_THROW(readAlone("whole.dcm", file));
    int errors = 0;
    for (std::size_t n = 0; n < file.size(); ++n) {
      try {
        readAlone("cut.dcm", file.substr(0, n));
        ADD_FAILURE() << "a file cut to " << n << " of " << file.size() << " bytes was read";
      } catch (const InputError& e) {
        ++errors;
        if (std::string(e.what()).rfind("cut.dcm: ", 0) != 0) {
          ADD_FAILURE() << "cut at " << n << ": " << e.what();
        }
      }
    }
    EXPECT_EQ(errors, static_cast<int>(file.size()));
  }
}

std::size_t find(const std::string& bytes, const std::string& what) {
  const std::size_t at = bytes.find(what);
  EXPECT_NE(at, std::string::npos) << "fixture lacks the bytes looked for";
  return at;
}

void putU32(std::string& bytes, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) bytes[at + i] = static_cast<char>((v >> (8 * i)) & 0xff);
}
void putU16(std::string& bytes, std::size_t at, std::uint16_t v) {
  bytes[at] = static_cast<char>(v & 0xff);
  bytes[at + 1] = static_cast<char>(v >> 8);
}

const std::string kPixelDataOW("\xe0\x7f\x10\x00OW\0\0", 8);
const std::string kPixelDataOB("\xe0\x7f\x10\x00OB\0\0", 8);
const std::string kRows("\x28\x00\x10\x00US\x02\x00", 8);
const std::string kColumns("\x28\x00\x11\x00US\x02\x00", 8);

TEST(DicomBasicReader, LyingLengthsAreRefusedBeforeAllocating) {
  test::BudgetOverride budget(64ull << 20);  // a lie taken at its word would exceed it
  const std::string good = oneSlice("little-endian-explicit");
  {
    std::string b = good;  // pixel data longer than the file
    putU32(b, find(b, kPixelDataOW) + 8, 0xfffffff0u);
    expectInputError("long.dcm", b, {"(7fe0,0010)", "declares 4294967280 bytes"});
  }
  {
    std::string b = good;  // 65535 x 65535 pixels claimed, 13 x 11 present
    putU16(b, find(b, kRows) + 8, 65535);
    putU16(b, find(b, kColumns) + 8, 65535);
    expectInputError("huge.dcm", b, {"pixel data has 286 bytes", "65535x65535"});
  }
  {
    std::string b = good;  // a short element whose length runs past the end
    const std::size_t at = find(b, std::string("\x20\x00\x32\x00"
                                               "DS",
                                               6));
    putU16(b, at + 6, 0xfff0);
    // 0xfff0 bytes from here pass the pixel data but not the end of the file.
    b.resize(std::min<std::size_t>(b.size(), at + 100));
    expectInputError("ds.dcm", b, {"(0020,0032)", "declares 65520 bytes"});
  }
  {
    std::string b = oneSlice("rle");  // RLE claims more pixels than it can hold
    putU16(b, find(b, kRows) + 8, 60000);
    putU16(b, find(b, kColumns) + 8, 60000);
    expectInputError("rle.dcm", b, {"can decode to at most", "RLE Lossless"});
  }
}

TEST(DicomBasicReader, RefusesOtherTransferSyntaxesNamingFileAndSyntax) {
  expectInputError("jpegls.dcm", oneSlice("jpeg-ls-lossless"),
                   {"JPEG-LS Lossless (1.2.840.10008.1.2.4.80)", "native tessera"});
  expectInputError("deflate.dcm", oneSlice("deflate"),
                   {"Deflated Explicit VR Little Endian (1.2.840.10008.1.2.1.99)"});
  test::TempDir dir;
  writeDicomSeries(noiseVolume(ScalarType::U16, 5), dir.path());
  transcode(dir.path(), EXS_BigEndianExplicit);
  expectInputError("big.dcm", readBytes(filesIn(dir.path())[0]),
                   {"Big Endian Explicit (1.2.840.10008.1.2.2)"});
  std::string odd = oneSlice("little-endian-explicit");
  const std::size_t at = find(odd, "1.2.840.10008.1.2.1");
  odd.replace(at, 19, "1.2.840.99999.1.2.3");
  expectInputError("odd.dcm", odd, {"'1.2.840.99999.1.2.3' (unknown)"});
  // In a folder, such a file is left out with a note when the series is whole without it.
}

std::uint32_t getU32(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(b[at + i]);
  return v;
}

// The RLE frame of a one-fragment file, after the basic offset table item;
// its size in `length`.
std::size_t rleFrame(const std::string& b, std::uint32_t& length) {
  const std::size_t table = find(b, kPixelDataOB) + 12;
  const std::size_t fragment = table + 8 + getU32(b, table + 4);
  length = getU32(b, fragment + 4);
  return fragment + 8;
}

TEST(DicomBasicReader, CorruptRleSegmentsAreInputErrors) {
  const std::string good = oneSlice("rle");
  ASSERT_NO_THROW(readAlone("good.dcm", good));
  std::uint32_t length = 0;
  const std::size_t frame = rleFrame(good, length);
  ASSERT_EQ(static_cast<unsigned char>(good[frame]), 2u) << "16-bit: two segments";
  {
    std::string b = good;
    putU32(b, frame, 3);
    expectInputError("segments.dcm", b, {"RLE header says 3 segments", "need 2"});
  }
  {
    std::string b = good;
    putU32(b, frame + 8, 0x7fffffff);
    expectInputError("offset.dcm", b, {"RLE segment", "corrupt offsets"});
  }
  {
    std::string b = good;  // two replicate runs of 128 into a segment of 13 x 11 bytes
    for (int i = 0; i < 4; ++i) b[frame + 64 + i] = static_cast<char>(0x81);
    expectInputError("run.dcm", b, {"RLE segment 1 decodes to more than the 143 bytes"});
  }
  {
    std::string b = good;  // the second segment empty
    putU32(b, frame + 8, length);
    expectInputError("short.dcm", b, {"RLE segment 2 ends after 0 of 143 bytes"});
  }
}

// A hand-made Part-10 file: explicit VR little endian elements.
std::string element(std::uint16_t g, std::uint16_t e, const std::string& vr,
                    const std::string& value, bool undefinedLength = false) {
  std::string b(4, '\0');
  putU16(b, 0, g);
  putU16(b, 2, e);
  b += vr;
  const bool longForm = vr == "OB" || vr == "OW" || vr == "SQ" || vr == "UN" || vr == "UT";
  if (longForm) {
    b += std::string(2, '\0');
    std::string len(4, '\0');
    putU32(len, 0, undefinedLength ? 0xffffffffu : static_cast<std::uint32_t>(value.size()));
    b += len;
  } else {
    std::string len(2, '\0');
    putU16(len, 0, static_cast<std::uint16_t>(value.size()));
    b += len;
  }
  return b + value;
}

std::string us(std::uint16_t v) {
  std::string b(2, '\0');
  putU16(b, 0, v);
  return b;
}

std::string delimiter(std::uint16_t e, std::uint32_t length = 0) {
  std::string b(8, '\0');
  putU16(b, 0, 0xfffe);
  putU16(b, 2, e);
  putU32(b, 4, length);
  return b;
}

// A 2x2 8-bit image, with `before` inserted before its pixel data.
std::string tinyImage(const std::string& before) {
  std::string f(128, '\0');
  f += "DICM";
  f += element(0x0002, 0x0010, "UI", std::string("1.2.840.10008.1.2.1\0", 20));
  f += element(0x0020, 0x000e, "UI", "1.2.3.4");
  f += before;
  f += element(0x0028, 0x0010, "US", us(2)) + element(0x0028, 0x0011, "US", us(2)) +
       element(0x0028, 0x0100, "US", us(8));
  f += element(0x7fe0, 0x0010, "OB", "\x01\x02\x03\x04");
  return f;
}

TEST(DicomBasicReader, SequencesAreSkippedAndMalformedOnesRefused) {
  // Defined and undefined lengths, nested: skipped, the image read.
  const std::string inner = element(0x0008, 0x0100, "SH", "CODE");
  const std::string definedItem =
      delimiter(0xe000, static_cast<std::uint32_t>(inner.size())) + inner;
  const std::string undefinedItem = delimiter(0xe000, 0xffffffffu) + inner +
                                    element(0x0040, 0x0260, "SQ", definedItem) + delimiter(0xe00d);
  const std::string sequences =
      element(0x0008, 0x1140, "SQ", definedItem) +
      element(0x0008, 0x1150, "SQ", undefinedItem + definedItem + delimiter(0xe0dd), true);
  const Volume v = readAlone("seq.dcm", tinyImage(sequences));
  EXPECT_EQ(v.dims(), glm::ivec3(2, 2, 1));
  EXPECT_EQ(v.valueAt(1, 1, 0), 4.0);

  // 1000 nested undefined-length sequences: refused, not a stack overflow.
  std::string deep;
  for (int i = 0; i < 1000; ++i) {
    deep += element(0x0008, 0x1150, "SQ", "", true) + delimiter(0xe000, 0xffffffffu);
  }
  expectInputError("deep.dcm", tinyImage(deep),
                   {"sequences nested deeper than 64 levels; refused"});
  // A sequence without its delimiter: what follows is no item, or the file ends.
  const std::string open = element(0x0008, 0x1150, "SQ", definedItem, true);
  expectInputError("open.dcm", tinyImage(open), {"sequence (0008,1150) holds (0028,0010)"});
  const std::string cut = tinyImage(open);
  expectInputError("cut.dcm", cut.substr(0, cut.find(open) + open.size()),
                   {"no Sequence Delimitation Item", "truncated"});
  expectInputError("undefined.dcm", tinyImage(element(0x0008, 0x0060, "UT", "", true)),
                   {"undefined length but VR UT"});
  expectInputError("vr.dcm", tinyImage(element(0x0008, 0x0060, "zz", "MR")),
                   {"has VR 'zz'", "no DICOM VR"});
  expectInputError("item.dcm", tinyImage(delimiter(0xe000, 0)), {"outside any sequence"});
}

// The bad-input corpus made for the DCMTK reader (scripts/make_bad_corpus.py):
// every folder is an InputError here too.
TEST(DicomBasicReader, BadCorpusFoldersAreInputErrors) {
  const fs::path corpus = fs::path(TESSERA_TEST_DATA_DIR) / "bad" / "dicom";
  ASSERT_TRUE(fs::is_directory(corpus)) << corpus;
  int folders = 0;
  for (const auto& e : fs::directory_iterator(corpus)) {
    if (!e.is_directory()) continue;
    ++folders;
    SCOPED_TRACE(e.path().filename().string());
    test::expectRejected<InputError>([&] { readDicomSeriesBasic(e.path()); }, {e.path().string()});
  }
  EXPECT_GE(folders, 10);
}

}  // namespace
}  // namespace tessera
