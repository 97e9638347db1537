#include "tessera/io/MetaImageReader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <vector>

#include "io/GeometryFixtures.h"
#include "io/IoFixtures.h"
#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/io/MetaImageWriter.h"
#include "tessera/io/NiftiReader.h"

namespace tessera {
namespace {

// The io fixtures are this suite's vocabulary.
using namespace test;

// zlib (RFC 1950) stream, as MetaIO writes for CompressedData = True.
std::string zlibBytes(std::string_view data) {
  uLongf len = compressBound(static_cast<uLong>(data.size()));
  std::string out(len, '\0');
  if (compress2(reinterpret_cast<Bytef*>(out.data()), &len,
                reinterpret_cast<const Bytef*>(data.data()), static_cast<uLong>(data.size()),
                Z_BEST_SPEED) != Z_OK) {
    throw std::runtime_error("compress2 failed");
  }
  out.resize(len);
  return out;
}

std::string header(const std::string& fields, const std::string& dims = "4 3 2",
                   const std::string& type = "MET_UCHAR", const std::string& data = "LOCAL") {
  return "ObjectType = Image\nNDims = 3\nBinaryData = True\n" + fields + "DimSize = " + dims +
         "\nElementType = " + type + "\nElementDataFile = " + data + "\n";
}

struct RoundTripCase {
  ScalarType type;
  const char* extension;
  bool compressed;
};

class MetaImageRoundTrip : public ::testing::TestWithParam<RoundTripCase> {};

TEST_P(MetaImageRoundTrip, PreservesDimsTypeSpacingOriginAndVoxels) {
  const RoundTripCase c = GetParam();
  TempDir dir;
  Volume v = randomVolume({7, 5, 3}, c.type, 42);
  v.setSpacing({0.3, 1.25, 2.0 / 3.0});
  v.setOrigin({-12.5, 0.1, 1e-3});
  const auto path = dir / (std::string("rt") + c.extension);
  writeMetaImage(v, path, c.compressed);
  expectSameVolume(v, readMetaImage(path));

  const std::string text = fileBytes(path);
  EXPECT_NE(text.find(c.compressed ? "CompressedData = True" : "CompressedData = False"),
            std::string::npos);
  if (std::string(c.extension) == ".mhd") {
    const auto data = dir / (c.compressed ? "rt.zraw" : "rt.raw");
    ASSERT_TRUE(std::filesystem::exists(data));
    EXPECT_NE(text.find("ElementDataFile = " + data.filename().string()), std::string::npos);
    if (!c.compressed) {
      EXPECT_EQ(std::filesystem::file_size(data), v.byteSize());
    }
  } else {
    EXPECT_NE(text.find("ElementDataFile = LOCAL"), std::string::npos);
  }
}

std::vector<RoundTripCase> roundTripCases() {
  std::vector<RoundTripCase> cases;
  for (ScalarType t : {ScalarType::U8, ScalarType::U16, ScalarType::I16, ScalarType::F32}) {
    for (const char* ext : {".mha", ".mhd"}) {
      for (bool z : {false, true}) cases.push_back({t, ext, z});
    }
  }
  return cases;
}

std::string roundTripName(const ::testing::TestParamInfo<RoundTripCase>& param) {
  return std::string(scalarTypeName(param.param.type)) + "_" + (param.param.extension + 1) +
         (param.param.compressed ? "_zlib" : "_raw");
}

INSTANTIATE_TEST_SUITE_P(MetaImage, MetaImageRoundTrip, ::testing::ValuesIn(roundTripCases()),
                         roundTripName);

TEST(MetaImageReader, CompressedDataSizeIsTheZlibStreamOnDisk) {
  TempDir dir;
  // Smooth data compresses well, so the stream is much smaller than the voxels.
  Volume v = Volume::allocate({160, 150, 70}, ScalarType::U16, "test");
  for (std::size_t i = 0; i < v.voxelCount(); ++i) v.setValueAtIndex(i, (i / 97) % 4000);
  writeMetaImage(v, dir / "big.mhd", true);
  const std::string text = fileBytes(dir / "big.mhd");
  const auto packed = std::filesystem::file_size(dir / "big.zraw");
  EXPECT_NE(text.find("CompressedDataSize = " + std::to_string(packed) + "\n"), std::string::npos);
  EXPECT_LT(packed, v.byteSize() / 4);
  expectSameVolume(v, readMetaImage(dir / "big.mhd"));

  Volume noise = randomVolume({160, 150, 70}, ScalarType::U16, 7);  // several inflate chunks
  writeMetaImage(noise, dir / "noise.mha", true);
  expectSameVolume(noise, readMetaImage(dir / "noise.mha"));
}

TEST(MetaImageReader, ReadsBigEndianDataWithEitherKey) {
  TempDir dir;
  std::vector<std::uint16_t> u(4 * 3 * 2);
  for (std::size_t i = 0; i < u.size(); ++i) u[i] = static_cast<std::uint16_t>(i * 2500 + 7);
  writeFile(dir / "u.mha",
            header("BinaryDataByteOrderMSB = True\n", "4 3 2", "MET_USHORT") + voxelBytes(u, true));
  const Volume a = readMetaImage(dir / "u.mha");
  EXPECT_EQ(a.type(), ScalarType::U16);
  for (std::size_t i = 0; i < u.size(); ++i) EXPECT_EQ(a.valueAtIndex(i), u[i]);

  std::vector<float> f(4 * 3 * 2);
  for (std::size_t i = 0; i < f.size(); ++i) f[i] = 0.75f * static_cast<float>(i) - 3.0f;
  writeFile(dir / "f.mha",
            header("ElementByteOrderMSB = True\nCompressedData = True\n", "4 3 2", "MET_FLOAT") +
                zlibBytes(voxelBytes(f, true)));
  const Volume b = readMetaImage(dir / "f.mha");
  EXPECT_EQ(b.type(), ScalarType::F32);
  for (std::size_t i = 0; i < f.size(); ++i) EXPECT_EQ(b.valueAtIndex(i), f[i]);
}

TEST(MetaImageReader, ReadsAnItkStyleHeaderWithSynonymsAndUnknownKeys) {
  TempDir dir;
  std::vector<std::int8_t> values(3 * 2 * 2);
  for (std::size_t i = 0; i < values.size(); ++i)
    values[i] = static_cast<std::int8_t>(i * 20 - 110);
  // 4-D with a last axis of 1, ElementSize instead of ElementSpacing, Origin
  // instead of Offset, CRLF line ends, fields MetaIO has and we ignore.
  writeFile(dir / "c.mha",
            "ObjectType = Image\r\nNDims = 4\r\nBinaryData = True\r\n"
            "BinaryDataByteOrderMSB = False\r\nCompressedData = False\r\n"
            "TransformMatrix = 1 0 0 0 1 0 0 0 1\r\nOrigin = 1.5 -2 3 0\r\n"
            "CenterOfRotation = 0 0 0\r\nAnatomicalOrientation = RAI\r\nModality = MET_MOD_CT\r\n"
            "ElementSize = 0.5 0.25 4 1\r\nDimSize = 3 2 2 1\r\nSomethingNew = 42\r\n"
            "ElementType = MET_CHAR\r\nElementDataFile = LOCAL\r\n" +
                voxelBytes(values, false));
  const Volume v = readMetaImage(dir / "c.mha");
  EXPECT_EQ(v.dims(), glm::ivec3(3, 2, 2));
  EXPECT_EQ(v.type(), ScalarType::I16);  // int8 widened
  EXPECT_EQ(v.spacing(), glm::dvec3(0.5, 0.25, 4.0));
  // Origin is LPS (ITK's frame): (1.5, -2, 3) LPS = (-1.5, 2, 3) RAS.
  EXPECT_EQ(v.origin(), glm::dvec3(-1.5, 2.0, 3.0));
  for (std::size_t i = 0; i < values.size(); ++i) EXPECT_EQ(v.valueAtIndex(i), values[i]);
  EXPECT_NE(v.description().find("widened to i16"), std::string::npos);
}

TEST(MetaImageReader, ConvertsIntUintAndDoubleToFloat) {
  TempDir dir;
  std::vector<std::int32_t> i32 = {-100000, 0, 7, 2000000, -1, 65536, 3, 4};
  writeFile(dir / "i.mha", header("", "2 2 2", "MET_INT") + voxelBytes(i32, false));
  std::vector<std::uint32_t> u32 = {0, 1, 4000000, 16777216, 9, 8, 7, 6};
  writeFile(dir / "u.mha", header("", "2 2 2", "MET_UINT") + voxelBytes(u32, false));
  std::vector<double> f64 = {0.5, -1.25, 1e10, 3, 4, 5, 6, 7};
  writeFile(dir / "d.mha", header("", "2 2 2", "MET_DOUBLE") + voxelBytes(f64, false));
  const Volume a = readMetaImage(dir / "i.mha");
  const Volume b = readMetaImage(dir / "u.mha");
  const Volume c = readMetaImage(dir / "d.mha");
  for (const Volume* v : {&a, &b, &c}) {
    EXPECT_EQ(v->type(), ScalarType::F32);
    EXPECT_NE(v->description().find("converted to f32"), std::string::npos);
  }
  for (std::size_t i = 0; i < 8; ++i) {
    EXPECT_EQ(a.valueAtIndex(i), static_cast<float>(i32[i]));
    EXPECT_EQ(b.valueAtIndex(i), static_cast<float>(u32[i]));
    EXPECT_EQ(c.valueAtIndex(i), static_cast<float>(f64[i]));
  }
}

TEST(MetaImageReader, DetachedDataRelativeToTheHeaderWithHeaderSize) {
  TempDir dir;
  std::filesystem::create_directories(dir / "data");
  std::vector<std::int16_t> values(4 * 3 * 2);
  for (std::size_t i = 0; i < values.size(); ++i) {
    values[i] = static_cast<std::int16_t>(i * 97 - 1000);
  }
  writeFile(dir / "data" / "v.raw", std::string(100, 'J') + voxelBytes(values, false));
  writeFile(dir / "skip.mhd", header("HeaderSize = 100\n", "4 3 2", "MET_SHORT", "data/v.raw"));
  writeFile(dir / "end.mhd", header("HeaderSize = -1\n", "4 3 2", "MET_SHORT", "data/v.raw"));
  for (const char* name : {"skip.mhd", "end.mhd"}) {
    const Volume v = readMetaImage(dir / name);
    EXPECT_EQ(v.type(), ScalarType::I16);
    for (std::size_t i = 0; i < values.size(); ++i) EXPECT_EQ(v.valueAtIndex(i), values[i]);
  }
  // Without CompressedDataSize the zlib stream runs to the end of the file.
  writeFile(dir / "data" / "v.zraw", zlibBytes(voxelBytes(values, false)));
  writeFile(dir / "z.mhd", header("CompressedData = True\n", "4 3 2", "MET_SHORT", "data/v.zraw"));
  const Volume z = readMetaImage(dir / "z.mhd");
  for (std::size_t i = 0; i < values.size(); ++i) EXPECT_EQ(z.valueAtIndex(i), values[i]);
}

TEST(MetaImageReader, Ch2RoundTripIsExact) {
  for (bool z : {false, true}) {
    SCOPED_TRACE(z ? "zlib" : "raw");
    expectCh2RoundTrips(
        {"ch2.mha", "ch2.mhd"},
        [z](const Volume& v, const auto& path) { writeMetaImage(v, path, z); },
        [](const auto& path) { return readMetaImage(path); });
  }
}

// ---- placement: TransformMatrix, Offset, AnatomicalOrientation (LPS) ----

TEST(MetaImageReader, TransformMatrixListsEachAxisDirectionInLps) {
  TempDir dir;
  // Axis i -> LPS (0, 1, 0) = posterior, j -> (-1, 0, 0) = right, k -> superior;
  // MetaIO names the sides the axes come from: "ALI".
  for (const char* keys : {"TransformMatrix = 0 1 0 -1 0 0 0 0 1\nOffset = 10 20 30\n",
                           "Rotation = 0 1 0 -1 0 0 0 0 1\nPosition = 10 20 30\n"}) {
    SCOPED_TRACE(keys);
    writeFile(dir / "t.mha",
              header(std::string(keys) + "AnatomicalOrientation = ALI\nElementSpacing = 2 3 4\n",
                     "2 2 2") +
                  std::string(8, '\x02'));
    const Volume v = readMetaImage(dir / "t.mha");
    glm::dmat4 expected(1.0);
    expected[0] = glm::dvec4(0, -2, 0, 0);  // RAS: anterior-to-posterior is -y
    expected[1] = glm::dvec4(3, 0, 0, 0);   // towards patient right is +x
    expected[2] = glm::dvec4(0, 0, 4, 0);
    expected[3] = glm::dvec4(-10, -20, 30, 1);
    test::expectAffineNear(v.indexToWorld(), expected, 0.0);
    EXPECT_EQ(orientationOf(v.direction()).code, "PRS");
    EXPECT_NE(v.geometrySource().find("(LPS, converted to RAS)"), std::string::npos);
    EXPECT_EQ(v.geometrySource().find("disagrees"), std::string::npos) << v.geometrySource();
  }
}

TEST(MetaImageReader, AnatomicalOrientationIsIgnoredLikeItkButADisagreementIsNoted) {
  TempDir dir;
  writeFile(dir / "t.mha", header("TransformMatrix = 0 1 0 -1 0 0 0 0 1\n"
                                  "AnatomicalOrientation = RAI\n",
                                  "2 2 2") +
                               std::string(8, '\x02'));
  const Volume v = readMetaImage(dir / "t.mha");
  EXPECT_EQ(orientationOf(v.direction()).code, "PRS");  // the matrix wins
  EXPECT_NE(v.geometrySource().find("AnatomicalOrientation RAI disagrees (ALI by the matrix)"),
            std::string::npos)
      << v.geometrySource();
}

TEST(MetaImageReader, NoTransformMatrixIsIdentityInLps) {
  TempDir dir;
  writeFile(dir / "t.mha", header("Offset = 1 2 3\n", "2 2 2") + std::string(8, '\x02'));
  const Volume v = readMetaImage(dir / "t.mha");
  EXPECT_EQ(orientationOf(v.direction()).code, "LPS");
  EXPECT_EQ(v.origin(), glm::dvec3(-1, -2, 3));
}

TEST(MetaImageWriter, WritesLpsTransformMatrixOffsetAndItksOrientationLetters) {
  TempDir dir;
  struct Case {
    glm::dmat4 affine;
    const char* matrix;
    const char* offset;
    const char* orientation;
  };
  glm::dmat4 lps(1.0);  // identity in LPS: ITK's default image
  lps[0][0] = -1;
  lps[1][1] = -1;
  const Case cases[] = {
      {lps, "TransformMatrix = 1 0 0 0 1 0 0 0 1\n", "Offset = 0 0 0\n",
       "AnatomicalOrientation = RAI\n"},
      {glm::dmat4(1.0), "TransformMatrix = -1 0 0 0 -1 0 0 0 1\n", "Offset = 0 0 0\n",
       "AnatomicalOrientation = LPI\n"},
      {test::lasAffine(), "TransformMatrix = 1 0 0 0 -1 0 0 0 1\n", "Offset = -90.5 126.25 -72\n",
       "AnatomicalOrientation = RPI\n"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.orientation);
    writeMetaImage(test::volumeWithAffine({3, 2, 2}, ScalarType::U8, c.affine), dir / "w.mha");
    const std::string text = fileBytes(dir / "w.mha");
    const std::string head = text.substr(0, text.find("ElementDataFile"));
    EXPECT_NE(head.find(c.matrix), std::string::npos) << head;
    EXPECT_NE(head.find(c.offset), std::string::npos) << head;
    EXPECT_NE(head.find(c.orientation), std::string::npos) << head;
    EXPECT_EQ(readMetaImage(dir / "w.mha").geometrySource().find("disagrees"), std::string::npos);
  }
}

// ---- malformed input ----

// A budget far below what the bad headers claim: any allocation made before
// the claim is checked would show up as a BudgetError instead.
constexpr std::uint64_t kSmallBudget = 16ull << 20;

TEST(MetaImageReaderRejects, WrongMagicAndBinaryJunk) {
  TempDir dir;
  const auto png = dir / "p.mha";
  writeFile(png, std::string("\x89PNG\r\n\x1a\n", 8) + std::string(64, '\0'));
  expectRejected<InputError>([&] { readMetaImage(png); }, {png.string(), "not a MetaImage file"});
  const auto pgm = dir / "g.mha";
  writeFile(pgm, "P5\n4 4\n255\n" + std::string(16, '\0'));
  expectRejected<InputError>([&] { readMetaImage(pgm); }, {pgm.string(), "not a MetaImage file"});
  // A header whose ElementDataFile is missing runs into the voxels.
  const auto junk = dir / "j.mha";
  writeFile(junk, "ObjectType = Image\nNDims = 3\n" + test::noiseBytes(4096));
  expectRejected<InputError>([&] { readMetaImage(junk); }, {junk.string()});
  const auto line = dir / "l.mha";
  writeFile(line, "NDims = 3\n" + std::string(200000, 'q'));
  expectRejected<InputError>([&] { readMetaImage(line); }, {line.string(), "header line longer"});
}

TEST(MetaImageReaderRejects, TransformMatricesThatCannotPlaceAVolume) {
  TempDir dir;
  const auto path = dir / "m.mha";
  const std::pair<std::string, std::string> cases[] = {
      {"TransformMatrix = 1 0 0 0 1 0\n", "TransformMatrix has 6 values, but NDims 3 needs 9"},
      {"Orientation = 1 0 0 0 0 0 0 0 1\n", "gives index axis 1 the direction (0 0 0)"},
      {"TransformMatrix = 1 0 0 1 0 0 0 0 1\n", "parallel"},
      {"TransformMatrix = 1 0 0 0 nan 0 0 0 1\n", "value 5 is nan"},
  };
  for (const auto& [fields, fragment] : cases) {
    writeFile(path, header(fields, "2 2 2") + std::string(8, '\0'));
    expectRejected<InputError>([&] { readMetaImage(path); }, {path.string(), fragment});
  }
}

TEST(MetaImageReaderRejects, MissingRequiredFields) {
  TempDir dir;
  const auto path = dir / "m.mha";
  writeFile(path, "ObjectType = Image\nNDims = 3\nElementType = MET_UCHAR\n");
  expectRejected<InputError>([&] { readMetaImage(path); }, {path.string(), "'DimSize'"});
  writeFile(path, "NDims = 3\nDimSize = 1 1 1\nElementType = MET_UCHAR\n");
  expectRejected<InputError>([&] { readMetaImage(path); }, {path.string(), "'ElementDataFile'"});
}

TEST(MetaImageReaderRejects, TruncatedData) {
  TempDir dir;
  const auto path = dir / "t.mha";
  writeFile(path, header("", "64 64 64") + std::string(64 * 64 * 63, '\1'));
  expectRejected<InputError>([&] { readMetaImage(path); },
                             {path.string(), "header says 64x64x64 u8", "file has"});
}

TEST(MetaImageReaderRejects, DimsTimesTypeLargerThanTheFile) {
  TempDir dir;
  test::BudgetOverride budget(kSmallBudget);
  writeFile(dir / "v.raw", std::string(1000, '\0'));
  const auto path = dir / "big.mhd";
  writeFile(path, header("", "1024 1024 1024", "MET_FLOAT", "v.raw"));
  expectRejected<InputError>([&] { readMetaImage(path); },
                             {path.string(), "1024x1024x1024 f32 = 4 GiB", "v.raw", "file has"});
}

TEST(MetaImageReaderRejects, ZeroNegativeOrNanSpacing) {
  TempDir dir;
  const auto path = dir / "s.mha";
  for (const std::string& line :
       {std::string("ElementSpacing = 1 0 1\n"), std::string("ElementSpacing = -1 1 1\n"),
        std::string("ElementSpacing = 1 1 nan\n"), std::string("ElementSize = 1 inf 1\n")}) {
    writeFile(path, header(line, "2 2 2") + std::string(8, '\0'));
    expectRejected<InputError>([&] { readMetaImage(path); }, {path.string(), "along axis"});
  }
  writeFile(path, header("ElementSpacing = 1 1\n", "2 2 2") + std::string(8, '\0'));
  expectRejected<InputError>([&] { readMetaImage(path); }, {"ElementSpacing has 2 values"});
  writeFile(path, header("Offset = 0 nan 0\n", "2 2 2") + std::string(8, '\0'));
  expectRejected<InputError>([&] { readMetaImage(path); }, {"Offset along axis 1"});
}

TEST(MetaImageReaderRejects, ZeroAndHugeDims) {
  TempDir dir;
  test::BudgetOverride budget(kSmallBudget);
  const auto path = dir / "d.mha";
  writeFile(path, header("", "4 0 4") + std::string(16, '\0'));
  expectRejected<InputError>([&] { readMetaImage(path); },
                             {path.string(), "DimSize along axis 1 is 0"});
  writeFile(path, header("", "2147483648 1 1") + std::string(16, '\0'));
  expectRejected<InputError>([&] { readMetaImage(path); }, {path.string(), "2147483648"});
  writeFile(path, header("", "-5 2 2") + std::string(16, '\0'));
  expectRejected<InputError>([&] { readMetaImage(path); }, {"is -5"});
  writeFile(path, header("", "4 99999999999999999999 4"));
  expectRejected<InputError>([&] { readMetaImage(path); }, {"not an integer"});
  writeFile(path, header("", "4 4") + std::string(16, '\0'));
  expectRejected<InputError>([&] { readMetaImage(path); }, {"DimSize has 2 values"});
}

TEST(MetaImageReaderRejects, UnsupportedTypeChannelsDimensionsAndEncodings) {
  TempDir dir;
  const auto path = dir / "u.mha";
  writeFile(path, header("", "2 2 2", "MET_LONG_LONG") + std::string(64, '\0'));
  expectRejected<InputError>([&] { readMetaImage(path); },
                             {path.string(), "MET_LONG_LONG", "not supported"});
  writeFile(path, header("ElementNumberOfChannels = 3\n", "2 2 2", "MET_UCHAR_ARRAY") +
                      std::string(24, '\0'));
  expectRejected<InputError>([&] { readMetaImage(path); }, {"ElementNumberOfChannels is 3"});
  writeFile(path,
            "ObjectType = Image\nNDims = 3\nBinaryData = False\nDimSize = 1 1 1\n"
            "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n1\n");
  expectRejected<InputError>([&] { readMetaImage(path); }, {"BinaryData = False", "not supported"});
  writeFile(path,
            "ObjectType = Image\nNDims = 2\nDimSize = 4 4\nElementType = MET_UCHAR\n"
            "ElementDataFile = LOCAL\n" +
                std::string(16, '\0'));
  expectRejected<InputError>([&] { readMetaImage(path); }, {"NDims is 2"});
  writeFile(path,
            "ObjectType = Image\nNDims = 4\nDimSize = 2 2 2 3\nElementType = MET_UCHAR\n"
            "ElementDataFile = LOCAL\n" +
                std::string(24, '\0'));
  expectRejected<InputError>([&] { readMetaImage(path); }, {"NDims is 4"});
  writeFile(path,
            "ObjectType = Mesh\nNDims = 3\nDimSize = 1 1 1\nElementType = MET_UCHAR\n"
            "ElementDataFile = LOCAL\n\1");
  expectRejected<InputError>([&] { readMetaImage(path); }, {"ObjectType is 'Mesh'"});
}

TEST(MetaImageReaderRejects, SeveralDataFiles) {
  TempDir dir;
  const auto path = dir / "l.mhd";
  writeFile(path, header("", "2 2 2", "MET_UCHAR", "LIST") + "s0.raw\ns1.raw\n");
  expectRejected<InputError>([&] { readMetaImage(path); }, {path.string(), "not supported"});
  writeFile(path, header("", "2 2 2", "MET_UCHAR", "slice%03d.raw 1 2 1"));
  expectRejected<InputError>([&] { readMetaImage(path); }, {path.string(), "not supported"});
}

TEST(MetaImageReaderRejects, MissingDetachedFile) {
  TempDir dir;
  const auto path = dir / "d.mhd";
  writeFile(path, header("", "2 2 2", "MET_UCHAR", "gone.raw"));
  expectRejected<InputError>([&] { readMetaImage(path); },
                             {path.string(), "gone.raw", "no such file"});
}

TEST(MetaImageReaderRejects, CompressedDataSizeBeyondTheFile) {
  TempDir dir;
  const std::string packed = zlibBytes(test::noiseBytes(32 * 32 * 32));
  const auto path = dir / "c.mha";
  writeFile(path, header("CompressedData = True\nCompressedDataSize = " +
                             std::to_string(packed.size() + 500) + "\n",
                         "32 32 32") +
                      packed);
  expectRejected<InputError>(
      [&] { readMetaImage(path); },
      {path.string(), "CompressedDataSize = " + std::to_string(packed.size() + 500),
       "has only " + std::to_string(packed.size())});
}

TEST(MetaImageReaderRejects, TruncatedOrCorruptZlibData) {
  TempDir dir;
  const std::string packed = zlibBytes(test::noiseBytes(64 * 64 * 64));
  const auto cut = dir / "cut.mha";
  writeFile(cut,
            header("CompressedData = True\n", "64 64 64") + packed.substr(0, packed.size() / 3));
  expectRejected<InputError>([&] { readMetaImage(cut); },
                             {cut.string(), "zlib data ends after", "of 262144 bytes"});
  const auto plain = dir / "plain.mha";
  writeFile(plain, header("CompressedData = True\n", "4 4 4") + std::string(64, 'z'));
  expectRejected<InputError>([&] { readMetaImage(plain); },
                             {plain.string(), "do not start a zlib stream"});
  std::string broken = packed;
  for (std::size_t i = 100; i < 400; ++i) broken[i] = static_cast<char>(broken[i] ^ 0x5a);
  const auto bad = dir / "bad.mha";
  writeFile(bad, header("CompressedData = True\n", "64 64 64") + broken);
  expectRejected<InputError>([&] { readMetaImage(bad); }, {bad.string()});
}

TEST(MetaImageReaderRejects, ZlibBombOverTheHostBudget) {
  TempDir dir;
  const auto path = dir / "bomb.mha";
  // 64 KiB of zeros claiming 4 GiB: refused before anything is inflated.
  writeFile(path, header("CompressedData = True\n", "1024 1024 1024", "MET_FLOAT") +
                      zlibBytes(std::string(1 << 16, '\0')));
  test::BudgetOverride budget(kSmallBudget);
  expectRejected<BudgetError>([&] { readMetaImage(path); }, {path.string(), "budget"});
}

TEST(MetaImageReaderRejects, ZlibClaimBeyondWhatDeflateCanHold) {
  TempDir dir;
  const auto path = dir / "liar.mha";
  writeFile(path,
            header("CompressedData = True\n", "512 512 512") + zlibBytes(std::string(1024, '\0')));
  test::BudgetOverride budget(4ull << 30);
  expectRejected<InputError>([&] { readMetaImage(path); },
                             {path.string(), "can inflate to at most", "1032:1"});
}

TEST(MetaImageReaderRejects, MissingFileAndDirectory) {
  TempDir dir;
  expectRejected<InputError>([&] { readMetaImage(dir / "nope.mha"); },
                             {"nope.mha", "no such file"});
  expectRejected<InputError>([&] { readMetaImage(dir.path()); }, {"is a directory"});
}

TEST(MetaImageWriter, RefusesOtherExtensionsAndUnwritablePaths) {
  TempDir dir;
  const Volume v = randomVolume({2, 2, 2}, ScalarType::U8, 1);
  expectRejected<InputError>([&] { writeMetaImage(v, dir / "v.nrrd"); }, {".mha", ".mhd"});
  expectRejected<Error>([&] { writeMetaImage(v, dir / "no-such-dir" / "v.mha"); },
                        {"no-such-dir", "cannot open for writing"});
}

}  // namespace
}  // namespace tessera
