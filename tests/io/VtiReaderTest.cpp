#include "tessera/io/VtiReader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <vector>

#include "io/GeometryFixtures.h"
#include "io/IoFixtures.h"
#include "tessera/core/Error.h"
#include "tessera/io/NiftiReader.h"
#include "tessera/io/VtiWriter.h"

namespace tessera {
namespace {

// The io fixtures are this suite's vocabulary.
using namespace test;

// ---- building VTK XML files by hand, the way vtkXMLWriter lays them out ----

std::string base64(std::string_view bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const auto b = [&](std::size_t k) { return static_cast<unsigned char>(bytes[i + k]); };
    const std::uint32_t v = (b(0) << 16) | (b(1) << 8) | b(2);
    for (int s = 18; s >= 0; s -= 6) out += kAlphabet[(v >> s) & 63];
  }
  const std::size_t rest = bytes.size() - i;
  if (rest > 0) {
    std::uint32_t v = static_cast<unsigned char>(bytes[i]) << 16;
    if (rest == 2) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += rest == 2 ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

// One header word (UInt32 or UInt64) in the file's byte order.
std::string word(std::uint64_t v, bool header64, bool bigEndian) {
  if (header64) return voxelBytes(std::vector<std::uint64_t>{v}, bigEndian);
  return voxelBytes(std::vector<std::uint32_t>{static_cast<std::uint32_t>(v)}, bigEndian);
}

struct Payload {
  std::string header;
  std::string data;
  std::string joined() const { return header + data; }
};

Payload plainPayload(const std::string& data, bool header64, bool bigEndian) {
  return {word(data.size(), header64, bigEndian), data};
}

// vtkZLibDataCompressor: [#blocks, block size, last partial size, sizes...]
// then one zlib stream per block.
Payload zlibPayload(const std::string& data, std::size_t blockSize, bool header64, bool bigEndian) {
  Payload p;
  std::vector<std::string> blocks;
  for (std::size_t at = 0; at < data.size(); at += blockSize) {
    const std::size_t n = std::min(blockSize, data.size() - at);
    uLongf len = compressBound(static_cast<uLong>(n));
    std::string out(len, '\0');
    compress2(reinterpret_cast<Bytef*>(out.data()), &len,
              reinterpret_cast<const Bytef*>(data.data() + at), static_cast<uLong>(n), 6);
    out.resize(len);
    blocks.push_back(out);
  }
  p.header = word(blocks.size(), header64, bigEndian) + word(blockSize, header64, bigEndian) +
             word(data.size() % blockSize, header64, bigEndian);
  for (const auto& b : blocks) {
    p.header += word(b.size(), header64, bigEndian);
    p.data += b;
  }
  return p;
}

// Inline "binary" text as VTK writes it: a compressed array's header and
// blocks are separate base64 runs, a plain array is one run.
std::string inlineBase64(const Payload& p, bool compressed) {
  return compressed ? base64(p.header) + base64(p.data) : base64(p.joined());
}

struct VtiParts {
  std::string fileAttributes = "byte_order=\"LittleEndian\"";
  std::string extent = "0 3 0 2 0 1";
  std::string imageAttributes = "Origin=\"0 0 0\" Spacing=\"1 1 1\"";
  std::string pointDataAttributes;
  std::string arrays;    // DataArray elements
  std::string appended;  // the bytes after '_', empty for no <AppendedData>
  std::string appendedEncoding = "raw";
};

std::string vtiText(const VtiParts& v) {
  std::string s = "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\" " +
                  v.fileAttributes + ">\n  <ImageData WholeExtent=\"" + v.extent + "\" " +
                  v.imageAttributes + ">\n    <Piece Extent=\"" + v.extent +
                  "\">\n      <PointData " + v.pointDataAttributes + ">\n" + v.arrays +
                  "      </PointData>\n      <CellData>\n      </CellData>\n    </Piece>\n"
                  "  </ImageData>\n";
  if (!v.appended.empty()) {
    s += "  <AppendedData encoding=\"" + v.appendedEncoding + "\">\n   _" + v.appended +
         "\n  </AppendedData>\n";
  }
  return s + "</VTKFile>\n";
}

std::string dataArray(const std::string& type, const std::string& format,
                      const std::string& content, const std::string& extra = "") {
  std::string s = "        <DataArray type=\"" + type + "\" Name=\"v\" format=\"" + format + "\"" +
                  (extra.empty() ? "" : " " + extra);
  if (format == "appended") return s + "/>\n";
  return s + ">\n          " + content + "\n        </DataArray>\n";
}

// "1 1 1 ..." with n values.
std::string asciiOnes(std::size_t n) {
  std::string s;
  for (std::size_t i = 0; i < n; ++i) s += i == 0 ? "1" : " 1";
  return s;
}

template <class T>
std::vector<T> ramp(std::size_t n, double scale, double offset) {
  std::vector<T> v(n);
  for (std::size_t i = 0; i < n; ++i)
    v[i] = static_cast<T>(static_cast<double>(i) * scale + offset);
  return v;
}

template <class T>
void expectValues(const Volume& v, const std::vector<T>& values) {
  ASSERT_EQ(v.voxelCount(), values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    ASSERT_EQ(v.valueAtIndex(i), static_cast<double>(static_cast<float>(values[i]))) << "at " << i;
  }
}

// ---- round trips ----

class VtiRoundTrip : public ::testing::TestWithParam<std::tuple<ScalarType, bool>> {};

TEST_P(VtiRoundTrip, PreservesDimsTypeSpacingOriginAndVoxels) {
  const auto [type, zlib] = GetParam();
  TempDir dir;
  Volume v = randomVolume({7, 5, 3}, type, 42);
  v.setSpacing({0.3, 1.25, 2.0 / 3.0});
  v.setOrigin({-12.5, 0.1, 1e-3});
  writeVti(v, dir / "rt.vti", zlib);
  expectSameVolume(v, readVti(dir / "rt.vti"));
}

INSTANTIATE_TEST_SUITE_P(Vti, VtiRoundTrip,
                         ::testing::Combine(::testing::Values(ScalarType::U8, ScalarType::U16,
                                                              ScalarType::I16, ScalarType::F32),
                                            ::testing::Bool()));

TEST(VtiReader, ZlibRoundTripOfALargerVolumeSpansManyBlocks) {
  TempDir dir;
  Volume smooth = Volume::allocate({160, 150, 70}, ScalarType::U16, "test");
  for (std::size_t i = 0; i < smooth.voxelCount(); ++i) smooth.setValueAtIndex(i, (i / 97) % 4000);
  writeVti(smooth, dir / "smooth.vti", true);
  EXPECT_LT(std::filesystem::file_size(dir / "smooth.vti"), smooth.byteSize() / 4);
  expectSameVolume(smooth, readVti(dir / "smooth.vti"));
  const Volume noise = randomVolume({160, 150, 70}, ScalarType::F32, 3);
  writeVti(noise, dir / "noise.vti", true);
  expectSameVolume(noise, readVti(dir / "noise.vti"));
}

TEST(VtiReader, Ch2RoundTripIsExact) {
  for (bool z : {false, true}) {
    SCOPED_TRACE(z ? "zlib" : "raw");
    expectCh2RoundTrips(
        {"ch2.vti"}, [z](const Volume& v, const auto& path) { writeVti(v, path, z); },
        [](const auto& path) { return readVti(path); });
  }
}

// ---- the encodings other writers use ----

TEST(VtiReader, ReadsAsciiArrays) {
  TempDir dir;
  const auto i16 = ramp<std::int16_t>(24, -1234.0, 17.0);
  std::string text;
  for (auto x : i16) text += std::to_string(x) + (text.size() % 5 == 0 ? "\n" : " ");
  VtiParts parts;
  parts.arrays = dataArray("Int16", "ascii", text);
  writeFile(dir / "i.vti", vtiText(parts));
  const Volume a = readVti(dir / "i.vti");
  EXPECT_EQ(a.type(), ScalarType::I16);
  EXPECT_EQ(a.dims(), glm::ivec3(4, 3, 2));
  expectValues(a, i16);

  const auto f32 = ramp<float>(24, 0.1f, -1.3f);
  text.clear();
  for (auto x : f32) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g ", static_cast<double>(x));
    text += buf;
  }
  parts.arrays = dataArray("Float32", "ascii", text);
  writeFile(dir / "f.vti", vtiText(parts));
  const Volume b = readVti(dir / "f.vti");
  EXPECT_EQ(b.type(), ScalarType::F32);
  expectValues(b, f32);
}

TEST(VtiReader, ReadsInlineBase64PlainAndCompressed) {
  TempDir dir;
  const auto u16 = ramp<std::uint16_t>(24, 2500.0, 3.0);
  const std::string bytes = voxelBytes(u16, false);
  VtiParts parts;
  parts.arrays =
      dataArray("UInt16", "binary", inlineBase64(plainPayload(bytes, false, false), false));
  writeFile(dir / "plain.vti", vtiText(parts));
  const Volume a = readVti(dir / "plain.vti");
  EXPECT_EQ(a.type(), ScalarType::U16);
  expectValues(a, u16);

  // Three zlib blocks of 16 bytes, the last one partial (48 = 16 + 16 + 16: use 20).
  parts.fileAttributes = "byte_order=\"LittleEndian\" compressor=\"vtkZLibDataCompressor\"";
  parts.arrays =
      dataArray("UInt16", "binary", inlineBase64(zlibPayload(bytes, 20, false, false), true));
  writeFile(dir / "zlib.vti", vtiText(parts));
  const Volume b = readVti(dir / "zlib.vti");
  expectValues(b, u16);
  EXPECT_NE(b.description().find("zlib"), std::string::npos);
}

TEST(VtiReader, ReadsAppendedBase64) {
  TempDir dir;
  const auto i8 = ramp<std::int8_t>(24, -9.0, 100.0);
  const std::string bytes = voxelBytes(i8, false);
  VtiParts parts;
  parts.appendedEncoding = "base64";
  // A first array (another name) occupies the start of the appended data.
  const std::string other = base64(plainPayload(std::string(24, '\7'), false, false).joined());
  parts.pointDataAttributes = "Scalars=\"v\"";
  parts.arrays =
      "        <DataArray type=\"UInt8\" Name=\"w\" format=\"appended\" offset=\"0\"/>\n" +
      dataArray("Int8", "appended", "", "offset=\"" + std::to_string(other.size()) + "\"");
  parts.appended = other + base64(plainPayload(bytes, false, false).joined());
  writeFile(dir / "a.vti", vtiText(parts));
  const Volume a = readVti(dir / "a.vti");
  EXPECT_EQ(a.type(), ScalarType::I16);  // int8 widened
  expectValues(a, i8);

  parts.fileAttributes =
      "byte_order=\"LittleEndian\" header_type=\"UInt64\" "
      "compressor=\"vtkZLibDataCompressor\"";
  const std::string packedOther =
      inlineBase64(zlibPayload(std::string(24, '\7'), 8, true, false), true);
  parts.arrays =
      "        <DataArray type=\"UInt8\" Name=\"w\" format=\"appended\" offset=\"0\"/>\n" +
      dataArray("Int8", "appended", "", "offset=\"" + std::to_string(packedOther.size()) + "\"");
  parts.appended = packedOther + inlineBase64(zlibPayload(bytes, 10, true, false), true);
  writeFile(dir / "z.vti", vtiText(parts));
  expectValues(readVti(dir / "z.vti"), i8);
}

TEST(VtiReader, ReadsBigEndianFiles) {
  TempDir dir;
  const auto f32 = ramp<float>(24, 1.5, -7.0);
  const auto i32 = ramp<std::int32_t>(24, -100000.0, 5.0);
  for (bool zlib : {false, true}) {
    SCOPED_TRACE(zlib ? "zlib" : "plain");
    VtiParts parts;
    parts.fileAttributes = std::string("byte_order=\"BigEndian\" header_type=\"UInt32\"") +
                           (zlib ? " compressor=\"vtkZLibDataCompressor\"" : "");
    const std::string fb = voxelBytes(f32, true);
    const std::string ib = voxelBytes(i32, true);
    const Payload pf = zlib ? zlibPayload(fb, 32, false, true) : plainPayload(fb, false, true);
    const Payload pi = zlib ? zlibPayload(ib, 32, false, true) : plainPayload(ib, false, true);
    parts.arrays = dataArray("Float32", "appended", "", "offset=\"0\"");
    parts.appended = pf.joined();
    writeFile(dir / "f.vti", vtiText(parts));
    expectValues(readVti(dir / "f.vti"), f32);

    parts.arrays = dataArray("Int32", "binary", inlineBase64(pi, zlib));
    parts.appended.clear();
    writeFile(dir / "i.vti", vtiText(parts));
    const Volume v = readVti(dir / "i.vti");
    EXPECT_EQ(v.type(), ScalarType::F32);
    EXPECT_NE(v.description().find("converted to f32"), std::string::npos);
    expectValues(v, i32);
  }
}

TEST(VtiReader, ReadsAFileLikeParaViewWrites) {
  TempDir dir;
  // ParaView 5.x: appended raw, UInt64 headers, Direction, InformationKey
  // children inside a DataArray, field data, a second point array, and the
  // extent of a cropped image (not starting at 0).
  const auto u8 = ramp<std::uint8_t>(4 * 3 * 2, 7.0, 1.0);
  const auto f64 = ramp<double>(4 * 3 * 2, 0.25, -2.0);
  const std::string a = plainPayload(voxelBytes(f64, false), true, false).joined();
  const std::string b = plainPayload(voxelBytes(u8, false), true, false).joined();
  const std::string xml =
      "<?xml version=\"1.0\"?>\n"
      "<!-- written by hand, like vtkXMLImageDataWriter -->\n"
      "<VTKFile type=\"ImageData\" version=\"2.2\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n"
      "  <ImageData WholeExtent=\"2 5 10 12 -1 0\" Origin=\"1 2 3\" Spacing=\"0.5 0.5 1.5\" "
      "Direction=\"1 0 0 0 1 0 0 0 1\">\n"
      "  <FieldData>\n"
      "    <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">"
      "0</DataArray>\n"
      "  </FieldData>\n"
      "  <Piece Extent=\"2 5 10 12 -1 0\">\n"
      "    <PointData Scalars=\"ImageFile\">\n"
      "      <DataArray type=\"Float64\" Name=\"density\" format=\"appended\" RangeMin=\"-2\" "
      "RangeMax=\"3.75\" offset=\"0\"/>\n"
      "      <DataArray type=\"UInt8\" Name=\"ImageFile\" format=\"appended\" RangeMin=\"1\" "
      "RangeMax=\"162\" offset=\"" +
      std::to_string(a.size()) +
      "\">\n"
      "        <InformationKey name=\"L2_NORM_RANGE\" location=\"vtkDataArray\" length=\"2\">\n"
      "          <Value index=\"0\">\n            1\n          </Value>\n"
      "          <Value index=\"1\">\n            162\n          </Value>\n"
      "        </InformationKey>\n"
      "      </DataArray>\n"
      "    </PointData>\n"
      "    <CellData>\n    </CellData>\n"
      "  </Piece>\n"
      "  </ImageData>\n"
      "  <AppendedData encoding=\"raw\">\n   _" +
      a + b + "\n  </AppendedData>\n</VTKFile>\n";
  writeFile(dir / "pv.vti", xml);
  const Volume v = readVti(dir / "pv.vti");
  EXPECT_EQ(v.dims(), glm::ivec3(4, 3, 2));
  EXPECT_EQ(v.type(), ScalarType::U8);
  EXPECT_EQ(v.spacing(), glm::dvec3(0.5, 0.5, 1.5));
  // The first point of the extent sits at Origin + start * Spacing.
  EXPECT_EQ(v.origin(), glm::dvec3(1.0 + 2 * 0.5, 2.0 + 10 * 0.5, 3.0 - 1.5));
  expectValues(v, u8);
  EXPECT_NE(v.description().find("ImageFile"), std::string::npos);
}

TEST(VtiReader, DirectionIsRowMajorWithTheAxesAsColumns) {
  TempDir dir;
  // Rows (0 -1 0), (1 0 0), (0 0 1): axis i -> +y, j -> -x, k -> +z
  // (vtkImageData::ComputeTransforms: m4(r, c) = Direction[3r + c] * Spacing[c]).
  VtiParts parts;
  parts.extent = "1 2 0 1 0 1";
  parts.imageAttributes = "Origin=\"10 20 30\" Spacing=\"2 3 4\" Direction=\"0 -1 0 1 0 0 0 0 1\"";
  parts.arrays = dataArray("UInt8", "ascii", asciiOnes(8));
  writeFile(dir / "d.vti", vtiText(parts));
  const Volume v = readVti(dir / "d.vti");
  glm::dmat4 expected(1.0);
  expected[0] = glm::dvec4(0, 2, 0, 0);
  expected[1] = glm::dvec4(-3, 0, 0, 0);
  expected[2] = glm::dvec4(0, 0, 4, 0);
  // Voxel 0 is extent point (1, 0, 0): Origin + Direction * (1 * 2, 0, 0).
  expected[3] = glm::dvec4(10, 22, 30, 1);
  test::expectAffineNear(v.indexToWorld(), expected, 0.0);
  EXPECT_NE(v.geometrySource().find("taken as RAS"), std::string::npos) << v.geometrySource();
}

TEST(VtiReader, WritesTheDirectionRowByRow) {
  TempDir dir;
  const Volume v = test::volumeWithAffine({3, 2, 2}, ScalarType::U8, test::lasAffine());
  writeVti(v, dir / "las.vti", false);
  std::ifstream in(dir / "las.vti", std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_NE(ss.str().find("Origin=\"90.5 -126.25 -72\" Spacing=\"2 1.5 3\" "
                          "Direction=\"-1 0 0 0 1 0 0 0 1\""),
            std::string::npos)
      << ss.str().substr(0, 400);
}

TEST(VtiReader, WritesAFileVtkCanParse) {
  // The writer's own layout, checked field by field against the format.
  TempDir dir;
  Volume v = randomVolume({3, 2, 2}, ScalarType::I16, 5);
  writeVti(v, dir / "w.vti", false);
  std::ifstream in(dir / "w.vti", std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string s = ss.str();
  EXPECT_EQ(s.rfind("<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\"", 0), 0u);
  EXPECT_NE(s.find("header_type=\"UInt64\""), std::string::npos);
  EXPECT_NE(s.find("WholeExtent=\"0 2 0 1 0 1\""), std::string::npos);
  EXPECT_NE(s.find("type=\"Int16\""), std::string::npos);
  const std::size_t underscore = s.find('_', s.find("<AppendedData"));
  ASSERT_NE(underscore, std::string::npos);
  std::uint64_t count = 0;
  std::memcpy(&count, s.data() + underscore + 1, 8);
  EXPECT_EQ(count, v.byteSize());
  EXPECT_EQ(std::memcmp(s.data() + underscore + 9, v.bytes().data(), v.byteSize()), 0);
  EXPECT_EQ(s.substr(underscore + 9 + v.byteSize()), "\n  </AppendedData>\n</VTKFile>\n");
}

// ---- malformed input ----

constexpr std::uint64_t kSmallBudget = 16ull << 20;

VtiParts appendedU8(const std::string& extent, const std::string& payload) {
  VtiParts parts;
  parts.extent = extent;
  parts.arrays = dataArray("UInt8", "appended", "", "offset=\"0\"");
  parts.appended = payload;
  return parts;
}

TEST(VtiReaderRejects, ADirectionThatCannotPlaceAVolume) {
  TempDir dir;
  const auto path = dir / "d.vti";
  const std::pair<std::string, std::string> cases[] = {
      {"Direction=\"1 1 0 0 0 0 0 0 1\"", "parallel"},  // columns 1 and 2 alike
      {"Direction=\"1 0 0 0 0 0 0 0 1\"", "Direction column 2 (axis y) is (0 0 0)"},
      {"Direction=\"1 0 0 0 1 0 0 0 inf\"", "Direction value 9 is inf"},
  };
  for (const auto& [attribute, fragment] : cases) {
    VtiParts parts;
    parts.imageAttributes = "Origin=\"0 0 0\" Spacing=\"1 1 1\" " + attribute;
    parts.arrays = dataArray("UInt8", "ascii", asciiOnes(24));
    writeFile(path, vtiText(parts));
    expectRejected<InputError>([&] { readVti(path); }, {path.string(), fragment});
  }
}

TEST(VtiReaderRejects, NotXmlOrNotImageData) {
  TempDir dir;
  const auto path = dir / "x.vti";
  writeFile(path, "P5\n4 4\n255\n" + std::string(16, '\0'));
  expectRejected<InputError>([&] { readVti(path); }, {path.string(), "not an XML file"});
  writeFile(path, test::noiseBytes(1 << 20));
  expectRejected<InputError>([&] { readVti(path); }, {path.string()});
  writeFile(path, "<html><body>hi</body></html>");
  expectRejected<InputError>([&] { readVti(path); }, {path.string(), "<VTKFile>"});
  writeFile(path, "<VTKFile type=\"PolyData\" version=\"1.0\"><PolyData/></VTKFile>");
  expectRejected<InputError>([&] { readVti(path); }, {path.string(), "PolyData", "ImageData"});
  writeFile(path, "<VTKFile type=\"ImageData\"></VTKFile>");
  expectRejected<InputError>([&] { readVti(path); }, {path.string(), "no <ImageData>"});
  writeFile(path, "");
  expectRejected<InputError>([&] { readVti(path); }, {path.string(), "no element"});
}

TEST(VtiReaderRejects, UnterminatedOrMalformedXml) {
  TempDir dir;
  const auto path = dir / "u.vti";
  VtiParts parts;
  parts.arrays = dataArray("UInt8", "ascii", asciiOnes(24));
  const std::string good = vtiText(parts);
  writeFile(path, good.substr(0, good.find("</DataArray>")));
  expectRejected<InputError>([&] { readVti(path); },
                             {path.string(), "unterminated XML", "<DataArray>"});
  writeFile(path, good.substr(0, good.find("WholeExtent") + 16));
  expectRejected<InputError>([&] { readVti(path); }, {path.string(), "unterminated XML"});
  std::string swapped = good;
  swapped.replace(swapped.find("</PointData>"), 12, "</CellData> ");
  writeFile(path, swapped);
  expectRejected<InputError>([&] { readVti(path); }, {path.string(), "does not match"});
  writeFile(path, "<VTKFile type=\"ImageData\" a=\"1\" a=\"2\"></VTKFile>");
  expectRejected<InputError>([&] { readVti(path); }, {"appears twice"});
  writeFile(path, "<!-- never closed <VTKFile type=\"ImageData\"></VTKFile>");
  expectRejected<InputError>([&] { readVti(path); }, {"unterminated XML", "comment"});
  std::string deep;
  for (int i = 0; i < 200; ++i) deep += "<a>";
  writeFile(path, "<VTKFile type=\"ImageData\">" + deep);
  expectRejected<InputError>([&] { readVti(path); }, {"nested deeper than"});
  writeFile(path, "<VTKFile type=\"ImageData\" x=\"" + std::string(3 << 20, 'a') + "\">");
  expectRejected<InputError>([&] { readVti(path); }, {"longer than"});
}

TEST(VtiReaderRejects, TruncatedAppendedData) {
  TempDir dir;
  test::BudgetOverride budget(kSmallBudget);
  const auto path = dir / "t.vti";
  const std::string data = std::string(24, '\5');
  // The file ends after the header word and 10 of the 24 voxels.
  const std::string whole = vtiText(appendedU8("0 3 0 2 0 1", "@@"));
  writeFile(path, whole.substr(0, whole.find("_@@") + 1) + plainPayload(data, false, false).header +
                      data.substr(0, 10));
  expectRejected<InputError>([&] { readVti(path); },
                             {path.string(), "needs 24 bytes", "holds at most 10"});
}

TEST(VtiReaderRejects, ExtentLargerThanTheData) {
  TempDir dir;
  test::BudgetOverride budget(kSmallBudget);
  const auto path = dir / "e.vti";
  // Header word honest about 24 bytes, extent claiming 1024^3 points.
  writeFile(path, vtiText(appendedU8("0 1023 0 1023 0 1023",
                                     plainPayload(std::string(24, '\1'), false, false).joined())));
  expectRejected<InputError>([&] { readVti(path); },
                             {path.string(), "header says 24 bytes", "1024x1024x1024 u8"});
  // Header word lying along with the extent: the file still cannot hold it.
  writeFile(path, vtiText(appendedU8("0 1023 0 1023 0 1023",
                                     word(1u << 30, false, false) + std::string(24, '\1'))));
  expectRejected<InputError>([&] { readVti(path); }, {path.string(), "holds at most"});
  // Ascii text far too short for the extent.
  VtiParts parts;
  parts.extent = "0 1023 0 1023 0 1023";
  parts.arrays = dataArray("UInt8", "ascii", "1 2 3 4");
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {path.string(), "holds at most"});
}

TEST(VtiReaderRejects, ZeroNegativeOrNanSpacing) {
  TempDir dir;
  const auto path = dir / "s.vti";
  for (const char* spacing : {"1 0 1", "-1 1 1", "1 1 nan", "inf 1 1"}) {
    VtiParts parts =
        appendedU8("0 3 0 2 0 1", plainPayload(std::string(24, '\1'), false, false).joined());
    parts.imageAttributes = std::string("Origin=\"0 0 0\" Spacing=\"") + spacing + "\"";
    writeFile(path, vtiText(parts));
    expectRejected<InputError>([&] { readVti(path); }, {path.string(), "Spacing along"});
  }
  VtiParts parts =
      appendedU8("0 3 0 2 0 1", plainPayload(std::string(24, '\1'), false, false).joined());
  parts.imageAttributes = "Origin=\"0 0 0\" Spacing=\"1 1\"";
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {"Spacing", "has 2 values, expected 3"});
}

TEST(VtiReaderRejects, ZeroAndHugeExtents) {
  TempDir dir;
  test::BudgetOverride budget(kSmallBudget);
  const auto path = dir / "d.vti";
  const std::string payload = plainPayload(std::string(24, '\1'), false, false).joined();
  writeFile(path, vtiText(appendedU8("0 -1 0 2 0 1", payload)));
  expectRejected<InputError>([&] { readVti(path); }, {path.string(), "gives 0 points along x"});
  writeFile(path, vtiText(appendedU8("0 2147483647 0 0 0 0", payload)));
  expectRejected<InputError>([&] { readVti(path); },
                             {path.string(), "gives 2147483648 points along x"});
  writeFile(path, vtiText(appendedU8("0 3 0 2 0", payload)));
  expectRejected<InputError>([&] { readVti(path); }, {"expected 6"});
  writeFile(path, vtiText(appendedU8("0 3 0 2 0 99999999999999999999", payload)));
  expectRejected<InputError>([&] { readVti(path); }, {"not an integer"});
}

TEST(VtiReaderRejects, ZlibBombs) {
  TempDir dir;
  const auto path = dir / "bomb.vti";
  // One block of 64 KiB of zeros said to hold 4 GiB: beyond deflate's 1032:1.
  const std::string packed = zlibPayload(std::string(1 << 16, '\0'), 1 << 16, false, false).data;
  VtiParts parts = appendedU8("0 1023 0 1023 0 1023", "");
  parts.fileAttributes =
      "byte_order=\"LittleEndian\" header_type=\"UInt64\" "
      "compressor=\"vtkZLibDataCompressor\"";
  parts.arrays = dataArray("Float32", "appended", "", "offset=\"0\"");
  parts.appended = word(1, true, false) + word(4ull << 30, true, false) + word(0, true, false) +
                   word(packed.size(), true, false) + packed;
  writeFile(path, vtiText(parts));
  {
    test::BudgetOverride budget(8ull << 30);
    expectRejected<InputError>([&] { readVti(path); }, {path.string(), "1032:1"});
  }
  // 65536 blocks whose sizes add up to far more than the file holds.
  std::string headers =
      word(65536, true, false) + word(1 << 16, true, false) + word(0, true, false);
  for (int i = 0; i < 65536; ++i) headers += word(packed.size(), true, false);
  parts.appended = headers + packed;  // and only one block's data
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {path.string(), "more compressed bytes"});
  // A claim the file could back (60 MiB from 61000 bytes is within 1032:1)
  // but the host budget cannot: refused before any block is inflated.
  parts.extent = "0 1023 0 1023 0 59";
  parts.arrays = dataArray("UInt8", "appended", "", "offset=\"0\"");
  parts.appended = word(1, true, false) + word(60u << 20, true, false) + word(0, true, false) +
                   word(61000, true, false) + packed + test::noiseBytes(61000 - packed.size());
  writeFile(path, vtiText(parts));
  {
    test::BudgetOverride budget(kSmallBudget);
    expectRejected<BudgetError>([&] { readVti(path); }, {path.string(), "budget"});
  }
  // Block count claiming more header words than the file holds.
  parts.appended =
      word(1ull << 40, true, false) + word(1 << 16, true, false) + word(0, true, false) + packed;
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {path.string(), "blocks, but the file"});
}

TEST(VtiReaderRejects, CompressedSizesThatDoNotMatch) {
  TempDir dir;
  const auto path = dir / "m.vti";
  const std::string data = test::noiseBytes(24 * 4);
  VtiParts parts = appendedU8("0 3 0 2 0 1", "");
  parts.fileAttributes = "byte_order=\"LittleEndian\" compressor=\"vtkZLibDataCompressor\"";
  parts.arrays = dataArray("Float32", "appended", "", "offset=\"0\"");
  // Header's total (2 blocks of 64) disagrees with the extent (96 bytes).
  Payload p = zlibPayload(data, 64, false, false);
  p.header.replace(8, 4, word(64, false, false));  // last partial 32 -> 64: 128 bytes
  parts.appended = p.joined();
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {path.string(), "need", "96 bytes"});
  // Blocks that inflate to other than the header's 48 bytes each.
  const auto twoBlocks = [&](const std::string& first, const std::string& second) {
    const std::string b1 = zlibPayload(first, first.size(), false, false).data;
    const std::string b2 = zlibPayload(second, second.size(), false, false).data;
    return word(2, false, false) + word(48, false, false) + word(0, false, false) +
           word(b1.size(), false, false) + word(b2.size(), false, false) + b1 + b2;
  };
  parts.appended = twoBlocks(data.substr(0, 40), data.substr(48));
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); },
                             {path.string(), "zlib block 1 of 2 inflates to 40 bytes"});
  parts.appended = twoBlocks(data.substr(0, 48), data.substr(40));
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); },
                             {path.string(), "zlib block 2 of 2 inflates to more than"});
  // Compressed bytes that are not zlib.
  Payload s = zlibPayload(data, 48, false, false);
  for (std::size_t i = 0; i < s.data.size(); ++i) s.data[i] = static_cast<char>(s.data[i] ^ 0x33);
  parts.appended = s.joined();
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {path.string(), "not valid zlib data"});
}

TEST(VtiReaderRejects, Base64WithInvalidCharacters) {
  TempDir dir;
  const auto path = dir / "b.vti";
  std::string text = base64(plainPayload(std::string(24, '\3'), false, false).joined());
  text[10] = '!';
  VtiParts parts;
  parts.arrays = dataArray("UInt8", "binary", text);
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); },
                             {path.string(), "'!' is not a base64 character", "at byte"});
  text[10] = '=';
  parts.arrays = dataArray("UInt8", "binary", text);
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {path.string(), "padding"});
  parts.arrays = dataArray("UInt8", "binary", base64(std::string(2, '\0')));
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {path.string(), "ends inside its header"});
}

TEST(VtiReaderRejects, UnsupportedTypesComponentsAndEncodings) {
  TempDir dir;
  const auto path = dir / "u.vti";
  const std::string payload = plainPayload(std::string(24 * 8, '\1'), false, false).joined();
  VtiParts parts = appendedU8("0 3 0 2 0 1", payload);
  parts.arrays = dataArray("Int64", "appended", "", "offset=\"0\"");
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {path.string(), "Int64", "not supported"});
  parts.arrays = dataArray("UInt8", "appended", "", "NumberOfComponents=\"3\" offset=\"0\"");
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {"3 components"});
  parts.arrays = dataArray("UInt8", "appended", "", "offset=\"0\"");
  parts.fileAttributes = "byte_order=\"LittleEndian\" compressor=\"vtkLZ4DataCompressor\"";
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {"vtkLZ4DataCompressor", "not supported"});
  parts.fileAttributes = "byte_order=\"Middle\"";
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {"byte_order", "Middle"});
  parts.fileAttributes = "header_type=\"UInt16\"";
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {"header_type", "UInt16"});
  parts.fileAttributes = "byte_order=\"LittleEndian\"";
  parts.appendedEncoding = "hex";
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {"encoding 'hex'", "not supported"});
  parts.appendedEncoding = "raw";
  parts.arrays = dataArray("UInt8", "appended", "", "offset=\"999999\"");
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {"appended offset 999999"});
  parts.arrays = dataArray("UInt8", "zip", "abc");
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {"format 'zip'"});
  parts.arrays = dataArray("UInt8", "ascii", asciiOnes(23) + " x");
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {"'x' is not a valid UInt8"});
  parts.arrays = dataArray("UInt8", "ascii",
                           "1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 "
                           "21 22 23 300");
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {"'300' is not a valid UInt8"});
}

TEST(VtiReaderRejects, MissingArraysAndAppendedData) {
  TempDir dir;
  const auto path = dir / "m.vti";
  VtiParts parts;
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {path.string(), "no point-data array"});
  parts.pointDataAttributes = "Scalars=\"density\"";
  parts.arrays = dataArray("UInt8", "ascii", "1");
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {"Scalars=\"density\""});
  parts.pointDataAttributes.clear();
  parts.arrays = dataArray("UInt8", "appended", "", "offset=\"0\"");
  writeFile(path, vtiText(parts));
  expectRejected<InputError>([&] { readVti(path); }, {"no <AppendedData>"});
}

TEST(VtiReaderRejects, MissingFileAndDirectory) {
  TempDir dir;
  expectRejected<InputError>([&] { readVti(dir / "nope.vti"); }, {"nope.vti", "no such file"});
  expectRejected<InputError>([&] { readVti(dir.path()); }, {"is a directory"});
}

TEST(VtiWriter, ReportsAnUnwritablePath) {
  TempDir dir;
  const Volume v = randomVolume({2, 2, 2}, ScalarType::U8, 1);
  expectRejected<Error>([&] { writeVti(v, dir / "no-such-dir" / "v.vti"); },
                        {"no-such-dir", "cannot open for writing"});
}

}  // namespace
}  // namespace tessera
