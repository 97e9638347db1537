#include "tessera/io/PvmReader.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "io/IoFixtures.h"
#include "io/PvmDds.h"
#include "tessera/core/Error.h"
#include "tessera/io/NiftiReader.h"
#include "tessera/io/PvmWriter.h"

namespace tessera {
namespace {

using namespace std::string_literals;
using io_detail::DdsVersion;
// The io fixtures are this suite's vocabulary.
using namespace test;

// The geometry of the random volumes written here.
const test::RandomVolumeOptions kPlaced{.spacing = {0.5, 1.25, 3.0}, .origin = {-90.5, 12.25, 0.1}};

std::span<const std::uint8_t> asBytes(const std::string& s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

std::string asString(const std::vector<std::uint8_t>& v) {
  return std::string(reinterpret_cast<const char*>(v.data()), v.size());
}

// "0101 1..." → bytes, most significant bit first, zero padded; spaces are
// for the reader.
std::string packBits(const std::string& bits) {
  std::string out;
  int used = 0;
  for (char c : bits) {
    if (c == ' ') continue;
    if (used == 0) out += '\0';
    if (c == '1') out.back() = static_cast<char>(out.back() | (0x80 >> used));
    used = (used + 1) % 8;
  }
  return out;
}

std::string bitsOf(unsigned value, int width) {
  std::string s;
  for (int b = width - 1; b >= 0; --b) s += ((value >> b) & 1u) ? '1' : '0';
  return s + ' ';
}

// ---- uncompressed PVM ----

TEST(PvmReader, RoundTripsU8Exactly) {
  TempDir dir;
  const Volume v = randomVolume({5, 4, 3}, ScalarType::U8, 1, kPlaced);
  writePvm(v, dir / "a.pvm");
  expectSameVolume(readPvm(dir / "a.pvm"), v);
}

TEST(PvmReader, RoundTripsU16ExactlyAcrossTheWholeRange) {
  TempDir dir;
  Volume v = randomVolume({7, 3, 2}, ScalarType::U16, 2, kPlaced);
  v.setValueAtIndex(0, 0);
  v.setValueAtIndex(1, 65535);
  v.setValueAtIndex(2, 0x0102);  // byte order shows
  v.setSpacing(glm::dvec3(0.1, 1.0 / 3.0, 1e-3));
  v.setOrigin(glm::dvec3(0.0, -1e9, 3.5));
  writePvm(v, dir / "a.pvm");
  expectSameVolume(readPvm(dir / "a.pvm"), v);
}

TEST(PvmReader, WritesPvm3WithBigEndianVoxelsAndFourTrailingStrings) {
  TempDir dir;
  Volume v = Volume::allocate({2, 1, 1}, ScalarType::U16);
  v.setValueAtIndex(0, 0x0102);
  v.setValueAtIndex(1, 0xfffe);
  v.setSpacing(glm::dvec3(0.5, 1.25, 3.0));
  v.setOrigin(glm::dvec3(1.0, -2.0, 0.5));
  writePvm(v, dir / "h.pvm");
  const std::string expected =
      "PVM3\n2 1 1\n0.5 1.25 3\n2\n\x01\x02\xff\xfe"s + "\0\0\0tessera origin: 1 -2 0.5\0"s;
  EXPECT_EQ(fileBytes(dir / "h.pvm"), expected);
}

TEST(PvmReader, ReadsAHandWrittenVersion1File) {
  TempDir dir;
  std::string voxels;
  for (int i = 0; i < 24; ++i) voxels += static_cast<char>(i * 10);
  writeFile(dir / "v1.pvm", "PVM\n4 3 2\n1\n" + voxels);
  const Volume v = readPvm(dir / "v1.pvm");
  EXPECT_EQ(v.dims(), glm::ivec3(4, 3, 2));
  EXPECT_EQ(v.type(), ScalarType::U8);
  EXPECT_EQ(v.spacing(), glm::dvec3(1.0));
  EXPECT_EQ(v.origin(), glm::dvec3(0.0));
  for (int i = 0; i < 24; ++i) EXPECT_EQ(v.valueAtIndex(static_cast<std::size_t>(i)), i * 10);
  EXPECT_EQ(v.valueAt(1, 2, 1), (1 + 4 * (2 + 3 * 1)) * 10);  // x fastest
}

TEST(PvmReader, ReadsAHandWrittenVersion2FileWithSpacingAnd16BitVoxels) {
  TempDir dir;
  std::string voxels;
  for (int i = 0; i < 12; ++i) {
    const int value = 1000 * i + 7;  // MSB first
    voxels += static_cast<char>(value >> 8);
    voxels += static_cast<char>(value & 0xff);
  }
  writeFile(dir / "v2.pvm", "PVM2\n3 2 2\n0.5 0.75 2\n2\n" + voxels);
  const Volume v = readPvm(dir / "v2.pvm");
  EXPECT_EQ(v.dims(), glm::ivec3(3, 2, 2));
  EXPECT_EQ(v.type(), ScalarType::U16);
  EXPECT_EQ(v.spacing(), glm::dvec3(0.5, 0.75, 2.0));
  for (int i = 0; i < 12; ++i) EXPECT_EQ(v.valueAtIndex(static_cast<std::size_t>(i)), 1000 * i + 7);
}

TEST(PvmReader, KeepsThePvm3StringsInTheDescription) {
  TempDir dir;
  writeFile(dir / "s.pvm",
            "PVM3\n1 1 1\n1 1 1\n1\n\x2a"s + "Bucky ball\0courtesy of AVS\0\0scanned 1999\0"s);
  const Volume v = readPvm(dir / "s.pvm");
  EXPECT_EQ(v.valueAt(0, 0, 0), 42.0);
  EXPECT_NE(v.description().find("description: Bucky ball"), std::string::npos) << v.description();
  EXPECT_NE(v.description().find("courtesy: courtesy of AVS"), std::string::npos);
  EXPECT_NE(v.description().find("comment: scanned 1999"), std::string::npos);
}

TEST(PvmReader, Ch2RoundTripsExactly) {
  expectCh2RoundTrips(
      {"ch2.pvm"}, [](const Volume& v, const auto& path) { writePvm(v, path); },
      [](const auto& path) { return readPvm(path); });
}

// ---- DDS-compressed PVM ----

TEST(PvmDds, DecodesAHandAssembledStreamWithPreviousBytePrediction) {
  // skip 1, strip 65536 (so only the previous byte predicts), one run of 8-bit
  // deltas (code 7) for header + 3 voxels, then one 0-bit run (code 0)
  // repeating the last voxel.
  const std::string payload = "PVM\n2 2 1\n1\n\x0a\xc8\x07";
  std::string bits = bitsOf(0, 2) + bitsOf(0xffff, 16) +
                     bitsOf(static_cast<unsigned>(payload.size()), 7) + bitsOf(7, 3);
  int previous = 0;
  for (char c : payload) {
    const int byte = static_cast<unsigned char>(c);
    bits += bitsOf(static_cast<unsigned>((byte - previous + 128) & 0xff), 8);
    previous = byte;
  }
  bits += bitsOf(1, 7) + bitsOf(0, 3);
  TempDir dir;
  writeFile(dir / "hand.pvm", "DDS v3d\n" + packBits(bits));
  const Volume v = readPvm(dir / "hand.pvm");
  EXPECT_EQ(v.dims(), glm::ivec3(2, 2, 1));
  EXPECT_EQ(v.valueAtIndex(0), 10.0);
  EXPECT_EQ(v.valueAtIndex(1), 200.0);
  EXPECT_EQ(v.valueAtIndex(2), 7.0);
  EXPECT_EQ(v.valueAtIndex(3), 7.0);
  EXPECT_NE(v.description().find("DDS v3d"), std::string::npos) << v.description();
}

TEST(PvmDds, DecodesTheRowAbovePredictorAnd2BitValues) {
  // strip 2: byte 3 is predicted as b2 + (b1 - b0) = 3 + 1 = 4; with every
  // delta +1 (2-bit value 3 = 1 + bias 2) the bytes are 1, 2, 3, 5.
  const std::string stream = "DDS v3d\n" + packBits(bitsOf(0, 2) + bitsOf(1, 16) + bitsOf(4, 7) +
                                                    bitsOf(1, 3) + "11 11 11 11");
  const auto info = io_detail::scanDds(asBytes(stream), "hand");
  EXPECT_EQ(info.skip, 1u);
  EXPECT_EQ(info.strip, 2u);
  EXPECT_EQ(info.decodedSize, 4u);
  EXPECT_EQ(io_detail::decodeDds(asBytes(stream), info).bytesAt(0, 4), "\x01\x02\x03\x05");
}

TEST(PvmDds, ReinterleavesPlanesOfTwoByteVoxels) {
  // skip 2: the decoded bytes 1, 2 | 3, 5 are plane 0 then plane 1, so the
  // file order is 1, 3, 2, 5.
  const std::string stream = "DDS v3d\n" + packBits(bitsOf(1, 2) + bitsOf(1, 16) + bitsOf(4, 7) +
                                                    bitsOf(1, 3) + "11 11 11 11");
  const auto info = io_detail::scanDds(asBytes(stream), "hand");
  EXPECT_EQ(info.skip, 2u);
  const auto payload = io_detail::decodeDds(asBytes(stream), info);
  EXPECT_EQ(payload.bytesAt(0, 4), "\x01\x03\x02\x05");
  EXPECT_EQ(payload.bytesAt(1, 2), "\x03\x02");
}

// Streams written by Roettger's own encoder (ddsbase.cpp writeDDSfile, run
// outside this repository) for the payloads below: ours must be identical
// and decode back.
std::string goldenPayload16() {
  std::string s = "PVM2\n6 5 4\n0.5 1 2\n2\n";
  for (unsigned i = 0; i < 120; ++i) {
    const unsigned v = (i * i * 37 + i * 11) % 65536;
    s += static_cast<char>(v >> 8);
    s += static_cast<char>(v & 0xff);
  }
  return s;
}

std::string goldenPayload8() {
  std::string s = "PVM\n7 3 2\n1\n";
  for (unsigned i = 0; i < 42; ++i) s += static_cast<char>((i * 13 + (i % 7) * (i % 7)) % 256);
  return s;
}

const std::string kGolden16 =
    "DDS v3d\n"
    "\x40\x01\x48\x7d\x07\xd3\xd9\x68\x06\xaa\x47\x5c\x35\x48\x08\xc8"
    "\xc0\x84\x4a\x4f\xdf\x60\xb0"s +
    std::string(113, '\xf0') +
    "\xa8\xe0\x5b\x1d\xf4\xc0\x06\x81"
    "\xf6\x05\x3c\x2b\xc3\xd8\x90\x3b\xa7\x15\xb6\xbb\x5d\xb6\xbb\x5d"
    "\xb6\xbb\x5d\xb5\xda\xed\xae\xda\xed\xb5\xdb\x5b\xb6\xbb\x6d\x76"
    "\xd7\x6d\x76\xbb\x6b\xb5\xdb\x5d\xb5\xdb\x6b\xb6\xb7\x6d\x76\xda"
    "\xed\xae\xda\xed\x40"s;

const std::string kGolden8 =
    "DDS v3d\n"
    "\x00\x01\x8a\x7d\x08\x67\x73\xda\xd6\x99\x36\xd8\xc6\x1e\xa2\xc8"
    "\xd7\xba\x38\x0b\xc6\xfb\xf7\x34\x40"s;

TEST(PvmDds, MatchesRoettgersEncoderByteForByte) {
  ASSERT_EQ(kGolden16.size(), 205u);
  ASSERT_EQ(kGolden8.size(), 33u);
  const std::string p16 = goldenPayload16();
  const std::string p8 = goldenPayload8();
  // writePVMvolume's choice: skip = components, strip = width.
  EXPECT_EQ(asString(io_detail::encodeDds(asBytes(p16), 2, 6, DdsVersion::V3d)), kGolden16);
  EXPECT_EQ(asString(io_detail::encodeDds(asBytes(p8), 1, 7, DdsVersion::V3d)), kGolden8);
  for (const auto& [golden, payload] : {std::pair{kGolden16, p16}, std::pair{kGolden8, p8}}) {
    const auto info = io_detail::scanDds(asBytes(golden), "golden");
    EXPECT_EQ(io_detail::decodeDds(asBytes(golden), info).bytesAt(0, info.decodedSize), payload);
  }
  TempDir dir;
  writeFile(dir / "golden16.pvm", kGolden16);
  const Volume v = readPvm(dir / "golden16.pvm");
  EXPECT_EQ(v.dims(), glm::ivec3(6, 5, 4));
  EXPECT_EQ(v.spacing(), glm::dvec3(0.5, 1.0, 2.0));
  for (unsigned i = 0; i < 120; ++i) EXPECT_EQ(v.valueAtIndex(i), (i * i * 37 + i * 11) % 65536);
}

TEST(PvmDds, EncoderAndDecoderAgreeOnEveryShapeOfData) {
  std::mt19937 rng(7);
  std::vector<std::string> payloads;
  for (std::size_t n : {1u, 2u, 5u, 1000u, 70001u}) {
    std::string noise(n, '\0'), smooth(n, '\0'), constant(n, '\x5a');
    for (std::size_t i = 0; i < n; ++i) {
      noise[i] = static_cast<char>(rng() & 0xff);
      smooth[i] = static_cast<char>((i / 3 + (rng() % 5)) & 0xff);
    }
    payloads.insert(payloads.end(), {noise, smooth, constant});
  }
  int cases = 0;
  for (const std::string& payload : payloads) {
    for (unsigned skip = 1; skip <= 4; ++skip) {
      for (unsigned strip : {1u, 2u, 7u, 256u, 65536u}) {
        for (DdsVersion version : {DdsVersion::V3d, DdsVersion::V3e}) {
          // A small interleave block exercises v3e's chunking on small data.
          const std::uint64_t block =
              version == DdsVersion::V3e ? 10 : io_detail::kDdsInterleaveBlock;
          const auto file = io_detail::encodeDds(asBytes(payload), skip, strip, version, block);
          const auto info = io_detail::scanDds(file, "encoded");
          ASSERT_EQ(info.decodedSize, payload.size());
          ASSERT_EQ(info.skip, skip);
          ASSERT_EQ(info.strip, strip);
          const auto decoded = io_detail::decodeDds(file, info, block);
          ASSERT_EQ(decoded.bytesAt(0, payload.size()), payload)
              << "size " << payload.size() << " skip " << skip << " strip " << strip;
          ++cases;
        }
      }
    }
  }
  EXPECT_EQ(cases, 15 * 4 * 5 * 2);
}

TEST(PvmDds, CompressesSmoothDataAndKeepsNoiseNearItsSize) {
  std::string smooth(100000, '\0');
  for (std::size_t i = 0; i < smooth.size(); ++i) smooth[i] = static_cast<char>(i / 1000);
  const auto packed = io_detail::encodeDds(asBytes(smooth), 1, 100, DdsVersion::V3d);
  EXPECT_LT(packed.size(), smooth.size() / 8);
}

void writeDdsPvm(const Volume& v, const std::filesystem::path& path, DdsVersion version) {
  writePvm(v, path);
  const std::string plain = fileBytes(path);
  // As ddsbase.cpp's writePVMvolume: skip = components, strip = width.
  const unsigned components = v.type() == ScalarType::U8 ? 1 : 2;
  writeFile(path, asString(io_detail::encodeDds(asBytes(plain), components,
                                                static_cast<unsigned>(v.dims().x), version)));
}

TEST(PvmReader, ReadsDdsCompressedU8AndU16Volumes) {
  TempDir dir;
  for (ScalarType type : {ScalarType::U8, ScalarType::U16}) {
    for (DdsVersion version : {DdsVersion::V3d, DdsVersion::V3e}) {
      const Volume v = randomVolume({9, 5, 4}, type, 3, kPlaced);
      const auto path = dir / "c.pvm";
      writeDdsPvm(v, path, version);
      ASSERT_EQ(fileBytes(path).substr(0, 4), "DDS ");
      expectSameVolume(readPvm(path), v);
    }
  }
}

TEST(PvmReader, Ch2RoundTripsThroughDdsCompression) {
  const auto writeDds = [](const Volume& v, const std::filesystem::path& path) {
    writeDdsPvm(v, path, DdsVersion::V3d);
    EXPECT_LT(std::filesystem::file_size(path), v.byteSize() / 2);
  };
  expectCh2RoundTrips({"ch2.pvm"}, writeDds, [](const auto& path) { return readPvm(path); });
}

// ---- writing ----

TEST(PvmReader, WriterRefusesTypesPvmCannotHold) {
  TempDir dir;
  for (ScalarType type : {ScalarType::I16, ScalarType::F32}) {
    const Volume v = Volume::allocate({2, 2, 2}, type);
    expectRejected<InputError>([&] { writePvm(v, dir / "x.pvm"); },
                               {(dir / "x.pvm").string(), "PVM stores only u8/u16"});
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(PvmReader, WriterIntoAMissingDirectoryFailsNamingThePath) {
  TempDir dir;
  expectWriteIntoMissingFolderFails(dir, dir / "missing" / "x.pvm",
                                    [](const Volume& v, const auto& path) { writePvm(v, path); });
}

TEST(PvmReader, ReplacingAFileLeavesNoTemporaryBehind) {
  TempDir dir;
  writeFile(dir / "a.pvm", "old");
  const Volume v = randomVolume({3, 3, 3}, ScalarType::U8, 4, kPlaced);
  writePvm(v, dir / "a.pvm");
  expectSameVolume(readPvm(dir / "a.pvm"), v);
  int entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++entries;
  EXPECT_EQ(entries, 1);
}

// ---- malformed input: each is refused with the file name and the problem ----

class PvmReaderRejects : public ::testing::Test {
 protected:
  // A header claiming more than the budget would be refused with a
  // BudgetError, which expectRejected<InputError> counts as a failure: the
  // checks below must come first.
  BudgetOverride budget_{64u << 20};
  TempDir dir_;

  void expectBad(const std::string& name, const std::string& bytes,
                 const std::vector<std::string>& fragments) {
    const auto path = dir_ / name;
    writeFile(path, bytes);
    std::vector<std::string> all{path.string()};
    all.insert(all.end(), fragments.begin(), fragments.end());
    expectRejected<InputError>([&] { readPvm(path); }, all);
  }
};

TEST_F(PvmReaderRejects, TruncatedVoxelData) {
  expectBad("short.pvm", "PVM\n4 3 2\n1\n" + std::string(20, 'x'),
            {"4x3x2 u8", "at offset 12", "needs 36 bytes, has 32"});
}

TEST_F(PvmReaderRejects, Truncated16BitVoxelData) {
  expectBad("short16.pvm", "PVM2\n4 3 2\n1 1 1\n2\n" + std::string(47, 'x'), {"4x3x2 u16"});
}

TEST_F(PvmReaderRejects, DimsFarLargerThanTheFile) {
  expectBad("huge.pvm", "PVM\n1048576 1048576 1048576\n2\n" + std::string(100, 'x'),
            {"1048576x1048576x1048576 u16", "file has"});
}

TEST_F(PvmReaderRejects, ZeroDims) {
  expectBad("zero.pvm", "PVM\n4 0 2\n1\n", {"height is 0"});
}

TEST_F(PvmReaderRejects, DimsOf2To31) {
  expectBad("big.pvm", "PVM\n2147483648 1 1\n1\n", {"width is 2147483648", "expected 1..1048576"});
}

TEST_F(PvmReaderRejects, DimsBeyond64Bits) {
  expectBad("overflow.pvm", "PVM\n4 3 99999999999999999999999\n1\n", {"depth", "out of range"});
}

TEST_F(PvmReaderRejects, NonNumericDims) {
  expectBad("text.pvm", "PVM\n4 three 2\n1\n", {"height 'three' is not a whole number"});
}

TEST_F(PvmReaderRejects, NegativeDims) {
  expectBad("negative.pvm", "PVM\n-4 3 2\n1\n", {"width is -4"});
}

TEST_F(PvmReaderRejects, TwoDims) {
  expectBad("two.pvm", "PVM\n4 3\n1\n", {"width height depth", "found 2 values"});
}

TEST_F(PvmReaderRejects, RgbComponents) {
  expectBad("rgb.pvm", "PVM\n2 2 2\n3\n" + std::string(24, 'x'), {"3 components", "RGB"});
  expectBad("rgba.pvm", "PVM\n2 2 2\n4\n" + std::string(32, 'x'), {"4 components", "RGBA"});
  expectBad("zero-c.pvm", "PVM\n2 2 2\n0\n", {"component count is 0"});
}

TEST_F(PvmReaderRejects, NaNZeroAndNegativeSpacing) {
  expectBad("nan.pvm", "PVM2\n2 2 2\nnan 1 1\n1\n" + std::string(8, 'x'), {"spacing x is nan"});
  expectBad("zero-s.pvm", "PVM2\n2 2 2\n1 0 1\n1\n" + std::string(8, 'x'), {"spacing y is 0"});
  expectBad("neg-s.pvm", "PVM3\n2 2 2\n1 1 -2\n1\n" + std::string(8, 'x'), {"spacing z is -2"});
  expectBad("word-s.pvm", "PVM3\n2 2 2\n1 1 wide\n1\n", {"'wide' is not a number"});
}

TEST_F(PvmReaderRejects, HeaderGarbage) {
  expectBad("noise.pvm", test::noiseBytes(4096), {"not a PVM file"});
  expectBad("empty.pvm", "", {"not a PVM file"});
  expectBad("pvm4.pvm", "PVM4\n2 2 2\n1\n", {"not a PVM file", "PVM4"});
  expectBad("endless.pvm", "PVM\n" + std::string(5000, '7'), {"no end of line"});
  expectBad("cut.pvm", "PVM2\n2 2 2\n", {"file ends where the voxel spacing should be"});
}

TEST_F(PvmReaderRejects, MissingFile) {
  const auto path = dir_ / "absent.pvm";
  expectRejected<InputError>([&] { readPvm(path); }, {path.string(), "no such file"});
}

TEST_F(PvmReaderRejects, TruncatedDdsStream) {
  const Volume v = randomVolume({16, 16, 16}, ScalarType::U8, 5, kPlaced);
  writeDdsPvm(v, dir_ / "full.pvm", DdsVersion::V3d);
  const std::string full = fileBytes(dir_ / "full.pvm");
  // A cut inside a run is seen as such; a cut between runs reads as the end
  // of the stream, and the decoded size falls short of the header.
  bool sawCutRun = false;
  for (std::size_t keep = 20; keep < full.size(); keep += 97) {
    expectBad("cut-dds.pvm", full.substr(0, keep), {"DDS"});
    try {
      readPvm(dir_ / "cut-dds.pvm");
    } catch (const InputError& e) {
      sawCutRun |= std::string(e.what()).find("DDS stream is truncated") != std::string::npos;
    }
  }
  EXPECT_TRUE(sawCutRun);
}

TEST_F(PvmReaderRejects, DdsStreamCutInsideItsHeader) {
  expectBad("dds-head.pvm", "DDS v3e\n\x01", {"ends inside its 18-bit header"});
}

TEST_F(PvmReaderRejects, DdsDataThatIsNotAPvm) {
  const std::string pnm = "P5\n2 2\n255\n\x01\x02\x03\x04";
  expectBad("pnm.pvm", asString(io_detail::encodeDds(asBytes(pnm), 1, 2, DdsVersion::V3d)),
            {"DDS data decodes to something that is not a PVM volume", "P5"});
}

TEST_F(PvmReaderRejects, DdsDataShorterThanItsHeaderSays) {
  const std::string plain = "PVM\n100 100 100\n1\n" + std::string(50, 'x');
  expectBad("short-dds.pvm",
            asString(io_detail::encodeDds(asBytes(plain), 1, 100, DdsVersion::V3d)),
            {"100x100x100 u8", "DDS data decode to 68 bytes"});
}

TEST_F(PvmReaderRejects, DdsNoise) {
  // Random bits after the magic decode to some bytes, never to a PVM header.
  for (unsigned seed = 1; seed <= 20; ++seed) {
    expectBad("dds-noise.pvm", "DDS v3d\n" + test::noiseBytes(20000, seed), {});
  }
}

TEST_F(PvmReaderRejects, BadOriginTag) {
  expectBad("origin.pvm", "PVM3\n1 1 1\n1 1 1\n1\n\x2a\0\0\0tessera origin: 1 two 3\0"s,
            {"three finite numbers"});
}

}  // namespace
}  // namespace tessera
