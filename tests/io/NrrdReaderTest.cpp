#include "tessera/io/NrrdReader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <random>
#include <vector>

#include <glm/geometric.hpp>

#include "io/GeometryFixtures.h"
#include "io/IoFixtures.h"
#include "tessera/core/Error.h"
#include "tessera/io/NrrdWriter.h"

namespace tessera {
namespace {

// The io fixtures are this suite's vocabulary.
using namespace test;

class NrrdRoundTrip : public ::testing::TestWithParam<std::tuple<ScalarType, bool>> {};

TEST_P(NrrdRoundTrip, PreservesDimsTypeSpacingOriginAndVoxels) {
  const auto [type, gzip] = GetParam();
  TempDir dir;
  Volume v = randomVolume({7, 5, 3}, type, 42);
  v.setSpacing({0.3, 1.25, 2.0 / 3.0});
  v.setOrigin({-12.5, 0.1, 1e-3});
  const auto path = dir / (gzip ? "rt.nrrd" : "rt-raw.nrrd");
  writeNrrd(v, path, gzip);
  const Volume r = readNrrd(path);
  expectSameVolume(v, r);
}

INSTANTIATE_TEST_SUITE_P(AllTypes, NrrdRoundTrip,
                         ::testing::Combine(::testing::Values(ScalarType::U8, ScalarType::U16,
                                                              ScalarType::I16, ScalarType::F32),
                                            ::testing::Bool()));

TEST(NrrdReader, GzipRoundTripOfALargerVolumeSpansSeveralChunks) {
  TempDir dir;
  Volume v = randomVolume({160, 150, 70}, ScalarType::U16, 7);  // 3.2 MiB, several chunks
  writeNrrd(v, dir / "big.nrrd", true);
  expectSameVolume(v, readNrrd(dir / "big.nrrd"));
  // Random data barely compresses, so the file really is gzip, not stored.
  EXPECT_GT(std::filesystem::file_size(dir / "big.nrrd"), 1u << 20);
}

TEST(NrrdReader, ReadsDetachedHeaderWithRelativeDataFile) {
  TempDir dir;
  std::filesystem::create_directories(dir / "data");
  std::vector<std::int16_t> values(4 * 3 * 2);
  for (std::size_t i = 0; i < values.size(); ++i)
    values[i] = static_cast<std::int16_t>(i * 97 - 1000);
  writeFile(dir / "data" / "vol.raw", voxelBytes(values, false));
  writeFile(dir / "vol.nhdr",
            "NRRD0004\n"
            "type: short\n"
            "dimension: 3\n"
            "sizes: 4 3 2\n"
            "spacings: 0.5 0.5 2\n"
            "endian: little\n"
            "encoding: raw\n"
            "data file: data/vol.raw\n");
  const Volume v = readNrrd(dir / "vol.nhdr");
  EXPECT_EQ(v.dims(), glm::ivec3(4, 3, 2));
  EXPECT_EQ(v.type(), ScalarType::I16);
  EXPECT_EQ(v.spacing(), glm::dvec3(0.5, 0.5, 2.0));
  for (std::size_t i = 0; i < values.size(); ++i) EXPECT_EQ(v.valueAtIndex(i), values[i]);
}

TEST(NrrdReader, ReadsDetachedGzipDataFile) {
  TempDir dir;
  std::vector<std::uint8_t> values(6 * 5 * 4);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = static_cast<std::uint8_t>(i * 3);
  writeFile(dir / "vol.raw.gz", test::gzipBytes(voxelBytes(values, false)));
  writeFile(dir / "vol.nhdr",
            "NRRD0005\ntype: uchar\ndimension: 3\nsizes: 6 5 4\nencoding: gzip\n"
            "datafile: vol.raw.gz\n");
  const Volume v = readNrrd(dir / "vol.nhdr");
  EXPECT_EQ(v.dims(), glm::ivec3(6, 5, 4));
  for (std::size_t i = 0; i < values.size(); ++i) EXPECT_EQ(v.valueAtIndex(i), values[i]);
}

TEST(NrrdReader, SwapsBigEndianData) {
  TempDir dir;
  std::vector<float> fvalues(3 * 2 * 2);
  for (std::size_t i = 0; i < fvalues.size(); ++i) fvalues[i] = 1.5f * static_cast<float>(i) - 7.0f;
  writeFile(dir / "f.nrrd",
            "NRRD0004\ntype: float\ndimension: 3\nsizes: 3 2 2\nendian: big\nencoding: raw\n\n" +
                voxelBytes(fvalues, true));
  const Volume f = readNrrd(dir / "f.nrrd");
  EXPECT_EQ(f.type(), ScalarType::F32);
  for (std::size_t i = 0; i < fvalues.size(); ++i) EXPECT_EQ(f.valueAtIndex(i), fvalues[i]);

  std::vector<std::uint16_t> svalues(3 * 2 * 2);
  for (std::size_t i = 0; i < svalues.size(); ++i)
    svalues[i] = static_cast<std::uint16_t>(i * 5000 + 3);
  writeFile(dir / "s.nrrd",
            "NRRD0004\ntype: unsigned short\ndimension: 3\nsizes: 3 2 2\n"
            "endian: big\nencoding: gzip\n\n" +
                test::gzipBytes(voxelBytes(svalues, true)));
  const Volume s = readNrrd(dir / "s.nrrd");
  EXPECT_EQ(s.type(), ScalarType::U16);
  for (std::size_t i = 0; i < svalues.size(); ++i) EXPECT_EQ(s.valueAtIndex(i), svalues[i]);
}

TEST(NrrdReader, IgnoresCommentsAndKeyValuesAndAcceptsCrLf) {
  TempDir dir;
  std::vector<std::uint8_t> values(8);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = static_cast<std::uint8_t>(200 + i);
  writeFile(dir / "c.nrrd",
            "NRRD0004\r\n# a comment: with a colon\r\nmodality:=CT: yes\r\nType: uint8_t\r\n"
            "dimension: 3\r\nsizes: 2 2 2\r\nkinds: domain domain domain\r\n"
            "encoding: raw\r\ncontent: tiny\r\n\r\n" +
                voxelBytes(values, false));
  const Volume v = readNrrd(dir / "c.nrrd");
  EXPECT_EQ(v.dims(), glm::ivec3(2, 2, 2));
  for (std::size_t i = 0; i < values.size(); ++i) EXPECT_EQ(v.valueAtIndex(i), values[i]);
  EXPECT_NE(v.description().find("tiny"), std::string::npos);
}

TEST(NrrdReader, SpacingIsTheLengthOfEachSpaceDirection) {
  TempDir dir;
  // A 4-D file whose first axis is a size-1 "vector" axis without direction.
  writeFile(dir / "d.nrrd",
            "NRRD0004\ntype: uchar\ndimension: 4\nspace: left-posterior-superior\n"
            "sizes: 1 2 2 2\nspace directions: none (0,1.2,1.6) (3,0,0) (0, 0, -0.5)\n"
            "space origin: (1,2,3)\nencoding: raw\n\n" +
                std::string(8, '\x07'));
  const Volume v = readNrrd(dir / "d.nrrd");
  EXPECT_EQ(v.dims(), glm::ivec3(2, 2, 2));
  EXPECT_DOUBLE_EQ(v.spacing().x, 2.0);
  EXPECT_DOUBLE_EQ(v.spacing().y, 3.0);
  EXPECT_DOUBLE_EQ(v.spacing().z, 0.5);
  // left-posterior-superior: x and y negated into RAS.
  EXPECT_EQ(v.origin(), glm::dvec3(-1, -2, 3));
  EXPECT_NEAR(glm::distance(v.direction()[0], glm::dvec3(0, -0.6, 0.8)), 0.0, 1e-12);
  EXPECT_EQ(v.direction()[1], glm::dvec3(-1, 0, 0));
  EXPECT_EQ(v.direction()[2], glm::dvec3(0, 0, -1));
}

TEST(NrrdReader, ByteSkipMinusOneReadsTheLastBytes) {
  TempDir dir;
  std::vector<std::uint8_t> values(2 * 3 * 4);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = static_cast<std::uint8_t>(i + 1);
  writeFile(dir / "v.den", std::string(100, 'J') + voxelBytes(values, false));
  writeFile(dir / "v.nhdr",
            "NRRD0001\ntype: uchar\ndimension: 3\nsizes: 2 3 4\nencoding: raw\n"
            "byte skip: -1\ndata file: ./v.den\n");
  const Volume v = readNrrd(dir / "v.nhdr");
  for (std::size_t i = 0; i < values.size(); ++i) EXPECT_EQ(v.valueAtIndex(i), values[i]);
}

TEST(NrrdReader, LineSkipThenByteSkip) {
  TempDir dir;
  std::vector<std::uint8_t> values(2 * 2 * 3);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = static_cast<std::uint8_t>(50 + i);
  writeFile(dir / "v.vtk", "# vtk\nline two\nXXXXX" + voxelBytes(values, false) + "trailer");
  writeFile(dir / "v.nhdr",
            "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 3\nencoding: raw\n"
            "line skip: 2\nbyte skip: 5\ndata file: v.vtk\n");
  const Volume v = readNrrd(dir / "v.nhdr");
  for (std::size_t i = 0; i < values.size(); ++i) EXPECT_EQ(v.valueAtIndex(i), values[i]);
}

// ---- placement: space, space directions, space origin ----

// A header whose axes are (1.2, 1.6, 0), (0, 0, 3), (0.4, -0.3, 0) from
// (10, -20, 30) in `spaceLine`'s space.
std::string spaceHeader(const std::string& spaceLine) {
  return "NRRD0005\ntype: uchar\ndimension: 3\nsizes: 2 2 2\n" + spaceLine +
         "space directions: (1.2,1.6,0) (0,0,3) (0.4, -0.3, 0)\n"
         "space origin: (10,-20,30)\nencoding: raw\n\n" +
         std::string(8, '\x01');
}

// Columns (glm) of the RAS affine expected for spaceHeader, given the signs
// that take the space's x and y to R and A.
glm::dmat4 expectedRas(double sx, double sy) {
  glm::dmat4 a(1.0);
  a[0] = glm::dvec4(sx * 1.2, sy * 1.6, 0, 0);
  a[1] = glm::dvec4(0, 0, 3, 0);
  a[2] = glm::dvec4(sx * 0.4, sy * -0.3, 0, 0);
  a[3] = glm::dvec4(sx * 10, sy * -20, 30, 1);
  return a;
}

TEST(NrrdReader, SpaceDirectionsAndOriginConvertToRasForEachSpace) {
  TempDir dir;
  struct Case {
    const char* line;
    double sx, sy;
    const char* source;
  };
  const Case cases[] = {
      {"space: right-anterior-superior\n", 1, 1, "(right-anterior-superior)"},
      {"space: RAS\n", 1, 1, "(RAS)"},
      {"space: left-posterior-superior\n", -1, -1, "left-posterior-superior, converted to RAS"},
      {"space: LPS\n", -1, -1, "converted to RAS"},
      {"space: Left-Anterior-Superior\n", -1, 1, "converted to RAS"},
      {"space: scanner-xyz\n", 1, 1, "scanner-xyz: no patient frame, taken as RAS"},
      {"space: 3D-right-handed\n", 1, 1, "no patient frame, taken as RAS"},
      {"space dimension: 3\n", 1, 1, "(space dimension 3: no patient frame, taken as RAS)"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.line);
    writeFile(dir / "s.nrrd", spaceHeader(c.line));
    const Volume v = readNrrd(dir / "s.nrrd");
    test::expectAffineNear(v.indexToWorld(), expectedRas(c.sx, c.sy), 1e-12);
    EXPECT_NE(v.geometrySource().find(c.source), std::string::npos) << v.geometrySource();
    EXPECT_DOUBLE_EQ(v.spacing().x, 2.0);
    EXPECT_DOUBLE_EQ(v.spacing().z, 0.5);
  }
}

TEST(NrrdReader, SpacingsWithoutSpaceDirectionsAreAxisAlignedRas) {
  TempDir dir;
  writeFile(dir / "s.nrrd",
            "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\n"
            "spacings: 0.5 2 3\nencoding: raw\n\n" +
                std::string(8, '\x01'));
  const Volume v = readNrrd(dir / "s.nrrd");
  EXPECT_EQ(v.direction(), glm::dmat3(1.0));
  EXPECT_EQ(v.spacing(), glm::dvec3(0.5, 2, 3));
  EXPECT_EQ(v.origin(), glm::dvec3(0.0));
  EXPECT_NE(v.geometrySource().find("spacings only"), std::string::npos);
}

TEST(NrrdWriter, WritesLpsSpaceDirectionsAndOriginAsSlicerDoes) {
  TempDir dir;
  const Volume v = test::volumeWithAffine({3, 2, 2}, ScalarType::U8, test::lasAffine());
  writeNrrd(v, dir / "las.nrrd");
  std::ifstream in(dir / "las.nrrd", std::ios::binary);
  std::string header, line;
  while (std::getline(in, line) && !line.empty()) header += line + "\n";
  // RAS diag(-2, 1.5, 3) from (90.5, -126.25, -72) is LPS diag(2, -1.5, 3)
  // from (-90.5, 126.25, -72).
  EXPECT_NE(header.find("space: left-posterior-superior\n"), std::string::npos) << header;
  EXPECT_NE(header.find("space directions: (2,0,0) (0,-1.5,0) (0,0,3)\n"), std::string::npos)
      << header;
  EXPECT_NE(header.find("space origin: (-90.5,126.25,-72)\n"), std::string::npos) << header;
  EXPECT_EQ(header.find("space dimension"), std::string::npos) << "Teem refuses both";
}

// ---- malformed input ----

std::string header3d(const std::string& extra, const std::string& type = "uchar",
                     const std::string& sizes = "4 4 4", const std::string& encoding = "raw") {
  return "NRRD0004\ntype: " + type + "\ndimension: 3\nsizes: " + sizes +
         "\nendian: little\nencoding: " + encoding + "\n" + extra;
}

TEST(NrrdReaderRejects, WrongMagic) {
  TempDir dir;
  writeFile(dir / "p.nrrd", "P5\n4 4\n255\n" + std::string(16, '\0'));
  expectRejected<InputError>([&] { readNrrd(dir / "p.nrrd"); },
                             {(dir / "p.nrrd").string(), "not a NRRD file"});
  writeFile(dir / "v.nrrd", "NRRD0009\ntype: uchar\n\n");
  expectRejected<InputError>([&] { readNrrd(dir / "v.nrrd"); }, {"NRRD0009"});
}

TEST(NrrdReaderRejects, MissingRequiredFields) {
  TempDir dir;
  writeFile(dir / "m.nrrd", "NRRD0004\ntype: uchar\ndimension: 3\nencoding: raw\n\n");
  expectRejected<InputError>([&] { readNrrd(dir / "m.nrrd"); },
                             {(dir / "m.nrrd").string(), "'sizes'"});
  writeFile(dir / "e.nrrd",
            "NRRD0004\ntype: short\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n\n\1\2");
  expectRejected<InputError>([&] { readNrrd(dir / "e.nrrd"); }, {"'endian'"});
}

TEST(NrrdReaderRejects, SizesLargerThanTheData) {
  TempDir dir;
  const auto path = dir / "s.nrrd";
  writeFile(path, header3d("\n", "ushort", "256 256 100") + std::string(1000, '\0'));
  expectRejected<InputError>(
      [&] { readNrrd(path); },
      {path.string(), "header says 256x256x100 u16 = 12.5 MiB", "file has", "needs 13107"});
}

TEST(NrrdReaderRejects, HugeAndZeroSizes) {
  TempDir dir;
  const auto path = dir / "h.nrrd";
  writeFile(path, header3d("\n", "uchar", "2147483647 2147483647 8"));
  expectRejected<InputError>([&] { readNrrd(path); }, {path.string(), "2147483647"});
  writeFile(path, header3d("\n", "uchar", "4 0 4"));
  expectRejected<InputError>([&] { readNrrd(path); }, {path.string(), "size of axis 1 is 0"});
  writeFile(path, header3d("\n", "uchar", "4 99999999999999999999 4"));
  expectRejected<InputError>([&] { readNrrd(path); }, {path.string(), "not an integer"});
}

TEST(NrrdReaderRejects, NanZeroOrNoneSpacing) {
  TempDir dir;
  const auto path = dir / "sp.nrrd";
  for (const std::string& line :
       {std::string("spacings: 1 nan 1\n"), std::string("spacings: 1 1 0\n"),
        std::string("spacings: -1 1 1\n"),
        std::string("space dimension: 3\nspace directions: (1,0,0) none (0,0,1)\n"),
        std::string("space dimension: 3\nspace directions: (1,0,0) (0,0,0) (0,0,1)\n")}) {
    writeFile(path, header3d(line + "\n") + std::string(64, '\0'));
    expectRejected<InputError>([&] { readNrrd(path); }, {path.string(), "axis"});
  }
}

TEST(NrrdReaderRejects, SpacesAndDirectionsThatCannotPlaceAVolume) {
  TempDir dir;
  const auto path = dir / "g.nrrd";
  const std::pair<std::string, std::string> cases[] = {
      {spaceHeader("space: right-anterior-superior-time\n"), "space-time"},
      {spaceHeader("space: sideways\n"), "'sideways' is not a NRRD 3-D space"},
      {spaceHeader("space dimension: 2\n"), "space dimension is 2"},
      {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nspace: RAS\n"
       "space directions: (1,0) (0,1,0) (0,0,1)\nencoding: raw\n\n" +
           std::string(8, '\0'),
       "has 2 components"},
      {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nspace: RAS\n"
       "space directions: (1,0,0) (2,0,0) (0,0,1)\nencoding: raw\n\n" +
           std::string(8, '\0'),
       "parallel"},
      {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nspace: RAS\n"
       "space directions: (1,0,0) (0,1,0) (0,0,1)\nspace origin: (1,nan,0)\n"
       "encoding: raw\n\n" +
           std::string(8, '\0'),
       "space origin (1,nan,0) is not finite"},
  };
  for (const auto& [text, fragment] : cases) {
    writeFile(path, text);
    expectRejected<InputError>([&] { readNrrd(path); }, {path.string(), fragment});
  }
}

TEST(NrrdReaderRejects, UnsupportedEncodingTypeAndDimension) {
  TempDir dir;
  const auto path = dir / "u.nrrd";
  writeFile(path, header3d("\n", "uchar", "4 4 4", "bzip2"));
  expectRejected<InputError>([&] { readNrrd(path); }, {path.string(), "bzip2", "not supported"});
  writeFile(path, header3d("\n", "uchar", "4 4 4", "ascii"));
  expectRejected<InputError>([&] { readNrrd(path); }, {"ascii", "not supported"});
  writeFile(path, header3d("\n", "block", "4 4 4"));
  expectRejected<InputError>([&] { readNrrd(path); }, {"block", "not supported"});
  writeFile(path, header3d("\n", "longlong", "4 4 4"));
  expectRejected<InputError>([&] { readNrrd(path); }, {"longlong", "not supported"});
  writeFile(path, "NRRD0004\ntype: uchar\ndimension: 2\nsizes: 4 4\nencoding: raw\n\n" +
                      std::string(16, '\0'));
  expectRejected<InputError>([&] { readNrrd(path); }, {path.string(), "dimension is 2"});
  writeFile(path, "NRRD0004\ntype: uchar\ndimension: 4\nsizes: 3 4 4 4\nencoding: raw\n\n" +
                      std::string(192, '\0'));
  expectRejected<InputError>([&] { readNrrd(path); }, {"dimension is 4"});
}

TEST(NrrdReaderRejects, SeveralDataFiles) {
  TempDir dir;
  const auto path = dir / "l.nhdr";
  writeFile(path, header3d("data file: LIST\nslice0.raw\nslice1.raw\n"));
  expectRejected<InputError>([&] { readNrrd(path); }, {path.string(), "not supported"});
  writeFile(path, header3d("data file: slice%03d.raw 0 3 1 2\n"));
  expectRejected<InputError>([&] { readNrrd(path); }, {path.string(), "not supported"});
}

TEST(NrrdReaderRejects, MissingDetachedDataFile) {
  TempDir dir;
  const auto path = dir / "d.nhdr";
  writeFile(path, header3d("data file: gone.raw\n"));
  expectRejected<InputError>([&] { readNrrd(path); }, {"gone.raw", "no such file"});
}

TEST(NrrdReaderRejects, TruncatedGzipData) {
  TempDir dir;
  const std::string voxels = test::noiseBytes(64 * 64 * 64);
  const std::string gz = test::gzipBytes(voxels);
  const auto path = dir / "cut.nrrd";
  writeFile(path, header3d("\n", "uchar", "64 64 64", "gzip") + gz.substr(0, gz.size() / 3));
  expectRejected<InputError>([&] { readNrrd(path); },
                             {path.string(), "gzip data ends after", "of 262144 bytes"});
}

TEST(NrrdReaderRejects, GzipDataThatIsNotGzip) {
  TempDir dir;
  const auto path = dir / "ng.nrrd";
  writeFile(path, header3d("\n", "uchar", "4 4 4", "gzip") + std::string(64, 'z'));
  expectRejected<InputError>([&] { readNrrd(path); }, {path.string(), "gzip magic"});
}

TEST(NrrdReaderRejects, GzipBombOverTheHostBudget) {
  TempDir dir;
  const auto path = dir / "bomb.nrrd";
  writeFile(path, header3d("\n", "float", "1024 1024 1024", "gzip") +
                      test::gzipBytes(std::string(1 << 16, '\0')));
  test::BudgetOverride budget(64ull << 20);
  expectRejected<BudgetError>([&] { readNrrd(path); }, {path.string(), "budget"});
}

TEST(NrrdReaderRejects, GzipClaimBeyondWhatDeflateCanHold) {
  TempDir dir;
  const auto path = dir / "liar.nrrd";
  writeFile(path, header3d("\n", "uchar", "512 512 512", "gzip") +
                      test::gzipBytes(std::string(1024, '\0')));
  test::BudgetOverride budget(4ull << 30);
  expectRejected<InputError>([&] { readNrrd(path); }, {path.string(), "can inflate to at most"});
}

TEST(NrrdReaderRejects, HeaderWithoutEndInBinaryJunk) {
  TempDir dir;
  const auto path = dir / "junk.nrrd";
  std::string text = "NRRD0004\ntype: uchar\n";
  text.append(200000, 'q');  // not "literal" + string: GCC 12 -Warray-bounds misfires on it
  writeFile(path, text);
  expectRejected<InputError>([&] { readNrrd(path); }, {path.string(), "header line longer"});
}

TEST(NrrdWriter, ReportsAnUnwritablePath) {
  TempDir dir;
  const Volume v = randomVolume({2, 2, 2}, ScalarType::U8, 1);
  expectRejected<Error>([&] { writeNrrd(v, dir / "no-such-dir" / "v.nrrd"); },
                        {"no-such-dir", "cannot open for writing"});
}

TEST(NrrdReaderRejects, MissingFileAndDirectory) {
  TempDir dir;
  expectRejected<InputError>([&] { readNrrd(dir / "nope.nrrd"); }, {"nope.nrrd", "no such file"});
  expectRejected<InputError>([&] { readNrrd(dir.path()); }, {"is a directory"});
}

}  // namespace
}  // namespace tessera
