#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/GeometryFixtures.h"
#include "io/IoFixtures.h"
#include "tessera/core/Error.h"
#include "tessera/io/NiftiReader.h"
#include "tessera/io/PvmReader.h"
#include "tessera/io/RawSidecarReader.h"
#include "tessera/io/RawSidecarWriter.h"

namespace tessera {
namespace {

// The io fixtures are this suite's vocabulary.
using namespace test;

// The geometry of the random volumes written here.
const test::RandomVolumeOptions kPlaced{.spacing = {0.5, 1.25, 0.1},
                                        .origin = {-90.5, 12.25, 1.0 / 3.0}};

constexpr ScalarType kAllTypes[] = {ScalarType::U8, ScalarType::U16, ScalarType::I16,
                                    ScalarType::F32};

TEST(RawSidecar, RoundTripsEveryTypeExactlyThroughEitherFile) {
  TempDir dir;
  for (ScalarType type : kAllTypes) {
    SCOPED_TRACE(std::string(scalarTypeName(type)));
    const Volume v = randomVolume({6, 5, 4}, type, 1, kPlaced);
    writeRawWithSidecar(v, dir / "vol.raw");
    ASSERT_TRUE(std::filesystem::exists(dir / "vol.raw.json"));
    EXPECT_EQ(std::filesystem::file_size(dir / "vol.raw"), v.byteSize());
    expectSameVolume(readRawWithSidecar(dir / "vol.raw"), v);
    expectSameVolume(readRawWithSidecar(dir / "vol.raw.json"), v);
  }
}

TEST(RawSidecar, WritesASidecarOtherToolsCanRead) {
  TempDir dir;
  writeRawWithSidecar(randomVolume({3, 2, 1}, ScalarType::I16, 2, kPlaced), dir / "x.raw");
  std::ifstream in(dir / "x.raw.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["dims"], nlohmann::json({3, 2, 1}));
  EXPECT_EQ(j["type"], "i16");
  EXPECT_EQ(j["endian"], "little");
  EXPECT_EQ(j["offset"], 0);
  EXPECT_EQ(j["file"], "x.raw");
  EXPECT_EQ(j["spacing"][2].get<double>(), 0.1);
  EXPECT_EQ(j["origin"][2].get<double>(), 1.0 / 3.0);
}

TEST(RawSidecar, DirectionListsTheUnitDirectionOfEachIndexAxis) {
  TempDir dir;
  writeFile(dir / "d.raw", std::string(8, '\x03'));
  // i -> anterior, j -> left, k -> superior (tilted 30 degrees towards A).
  writeFile(dir / "d.raw.json",
            R"({"dims": [2, 2, 2], "type": "u8", "spacing": [2, 3, 4], "origin": [1, 2, 3],
                "direction": [[0, 1, 0], [-1, 0, 0], [0, 0.5, 0.8660254037844386]]})");
  const Volume v = readRawWithSidecar(dir / "d.raw");
  glm::dmat4 expected(1.0);
  expected[0] = glm::dvec4(0, 2, 0, 0);
  expected[1] = glm::dvec4(-3, 0, 0, 0);
  expected[2] = glm::dvec4(0, 2, 4 * 0.8660254037844386, 0);
  expected[3] = glm::dvec4(1, 2, 3, 1);
  test::expectAffineNear(v.indexToWorld(), expected, 1e-12);
  EXPECT_NE(v.geometrySource().find("JSON sidecar direction"), std::string::npos);
}

TEST(RawSidecar, WritesTheDirectionAxisByAxis) {
  TempDir dir;
  writeRawWithSidecar(test::volumeWithAffine({3, 2, 1}, ScalarType::U8, test::lasAffine()),
                      dir / "las.raw");
  std::ifstream in(dir / "las.raw.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["direction"], nlohmann::json::parse("[[-1, 0, 0], [0, 1, 0], [0, 0, 1]]"));
  EXPECT_EQ(j["spacing"], nlohmann::json::parse("[2, 1.5, 3]"));
  EXPECT_EQ(j["origin"], nlohmann::json::parse("[90.5, -126.25, -72]"));
}

// Values of every type stored by hand in either byte order after an offset.
template <class T>
void checkHandWritten(const char* type, bool big, const std::vector<T>& values) {
  SCOPED_TRACE(std::string(type) + (big ? " big" : " little"));
  TempDir dir;
  constexpr std::size_t kOffset = 17;
  ByteImage raw(kOffset + values.size() * sizeof(T), big);
  raw.putText(0, "seventeen bytes!!");
  for (std::size_t i = 0; i < values.size(); ++i) raw.put<T>(kOffset + i * sizeof(T), values[i]);
  writeFile(dir / "h.dat", raw.bytes());
  writeFile(dir / "h.json",
            std::string(R"({"file": "h.dat", "dims": [3, 2, 1], "type": ")") + type +
                R"(", "endian": ")" + (big ? "big" : "little") +
                R"(", "offset": 17, "spacing": [2, 3, 4], "origin": [-1, 0.5, 8]})");
  const Volume v = readRawWithSidecar(dir / "h.json");
  EXPECT_EQ(v.dims(), glm::ivec3(3, 2, 1));
  EXPECT_EQ(v.spacing(), glm::dvec3(2.0, 3.0, 4.0));
  EXPECT_EQ(v.origin(), glm::dvec3(-1.0, 0.5, 8.0));
  for (std::size_t i = 0; i < values.size(); ++i) {
    EXPECT_EQ(v.valueAtIndex(i), static_cast<double>(values[i])) << "voxel " << i;
  }
}

TEST(RawSidecar, ReadsEitherByteOrderAfterAnOffset) {
  for (bool big : {false, true}) {
    checkHandWritten<std::uint8_t>("u8", big, {0, 1, 127, 128, 200, 255});
    checkHandWritten<std::uint16_t>("u16", big, {0, 1, 0x0102, 0x8000, 40000, 65535});
    checkHandWritten<std::int16_t>("i16", big, {-32768, -1, 0, 1, 0x0102, 32767});
    checkHandWritten<float>("f32", big, {-1.5f, 0.0f, 1e-30f, 3.25f, 1e30f, -0.125f});
  }
}

TEST(RawSidecar, FindsDataJsonBesideDataRawAndAppliesDefaults) {
  TempDir dir;
  writeFile(dir / "data.raw", std::string("\x01\x02\x03\x04\x05\x06\x07\x08", 8));
  writeFile(dir / "data.json", R"({"dims": [2, 2, 1], "type": "u16"})");
  const Volume v = readRawWithSidecar(dir / "data.raw");
  EXPECT_EQ(v.type(), ScalarType::U16);
  EXPECT_EQ(v.spacing(), glm::dvec3(1.0));
  EXPECT_EQ(v.origin(), glm::dvec3(0.0));
  EXPECT_EQ(v.valueAtIndex(0), 0x0201);  // little endian by default
  EXPECT_EQ(v.valueAtIndex(3), 0x0807);
}

TEST(RawSidecar, Ch2RoundTripsExactly) {
  expectCh2RoundTrips(
      {"ch2.raw"}, [](const Volume& v, const auto& path) { writeRawWithSidecar(v, path); },
      [](const auto& path) { return readRawWithSidecar(path); });
}

TEST(RawSidecar, WriterIntoAMissingDirectoryFailsNamingThePath) {
  TempDir dir;
  expectWriteIntoMissingFolderFails(
      dir, dir / "missing" / "x.raw",
      [](const Volume& v, const auto& path) { writeRawWithSidecar(v, path); });
}

// ---- malformed input: each is refused with the file name and the problem ----

class RawSidecarRejects : public ::testing::Test {
 protected:
  BudgetOverride budget_{64u << 20};  // a big allocation would be a BudgetError
  TempDir dir_;

  // data.raw holds `rawBytes` bytes; data.raw.json holds `json`.
  void expectBad(const std::string& json, std::size_t rawBytes,
                 const std::vector<std::string>& fragments) {
    writeFile(dir_ / "data.raw", std::string(rawBytes, '\x11'));
    writeFile(dir_ / "data.raw.json", json);
    std::vector<std::string> all{(dir_ / "data.raw.json").string()};
    all.insert(all.end(), fragments.begin(), fragments.end());
    expectRejected<InputError>([&] { readRawWithSidecar(dir_ / "data.raw"); }, all);
    expectRejected<InputError>([&] { readRawWithSidecar(dir_ / "data.raw.json"); }, all);
  }
};

TEST_F(RawSidecarRejects, MissingRawFile) {
  writeFile(dir_ / "lonely.json", R"({"dims": [2, 2, 2], "type": "u8", "file": "gone.raw"})");
  expectRejected<InputError>([&] { readRawWithSidecar(dir_ / "lonely.json"); },
                             {(dir_ / "lonely.json").string(), "gone.raw", "does not exist"});
  writeFile(dir_ / "alone.raw.json", R"({"dims": [2, 2, 2], "type": "u8"})");
  expectRejected<InputError>([&] { readRawWithSidecar(dir_ / "alone.raw.json"); },
                             {"alone.raw.json", "no \"file\" key", "alone.raw"});
  expectRejected<InputError>([&] { readRawWithSidecar(dir_ / "nothing.raw"); },
                             {(dir_ / "nothing.raw").string(), "no such file"});
}

TEST_F(RawSidecarRejects, MissingSidecar) {
  writeFile(dir_ / "bare.raw", "12345678");
  expectRejected<InputError>(
      [&] { readRawWithSidecar(dir_ / "bare.raw"); },
      {(dir_ / "bare.raw").string(), "no JSON sidecar", "bare.raw.json", "bare.json"});
}

TEST_F(RawSidecarRejects, DimsTimesTypeExceedTheFile) {
  expectBad(R"({"dims": [4, 4, 4], "type": "u16"})", 100,
            {"declares 4x4x4 u16 = 128 bytes", "has 100 bytes", "28 too few"});
  expectBad(R"({"dims": [4, 4, 4], "type": "u8", "offset": 50})", 100,
            {"at offset 50", "has 100 bytes", "14 too few"});
  expectBad(R"({"dims": [1048576, 1048576, 1048576], "type": "f32"})", 100,
            {"1048576x1048576x1048576 f32", "has 100 bytes"});
  expectBad(R"({"dims": [1, 1, 1], "type": "u8", "offset": 18446744073709551615})", 100,
            {"offset 18446744073709551615 lies beyond the end"});
}

TEST_F(RawSidecarRejects, FileLargerThanDeclared) {
  expectBad(R"({"dims": [4, 4, 4], "type": "u8"})", 100, {"36 more than declared"});
}

TEST_F(RawSidecarRejects, BadType) {
  expectBad(R"({"dims": [2, 2, 2], "type": "float64"})", 8,
            {"type is \"float64\"", "\"u8\", \"u16\", \"i16\" or \"f32\""});
  expectBad(R"({"dims": [2, 2, 2], "type": 8})", 8, {"type is 8, expected a string"});
  expectBad(R"({"dims": [2, 2, 2]})", 8, {"no \"type\""});
}

TEST_F(RawSidecarRejects, UnknownKey) {
  expectBad(R"({"dims": [2, 2, 2], "type": "u8", "spacings": [1, 1, 1]})", 8,
            {"unknown key \"spacings\"", "dims, type, spacing"});
}

TEST_F(RawSidecarRejects, MalformedJson) {
  expectBad(R"({"dims": [2, 2, 2], "type": "u8",})", 8, {"malformed JSON"});
  expectBad("", 8, {"malformed JSON"});
  expectBad(test::noiseBytes(300), 8, {"malformed JSON"});
  expectBad(R"([2, 2, 2])", 8, {"expected a JSON object"});
}

TEST_F(RawSidecarRejects, NaNZeroAndNegativeSpacing) {
  // JSON has no NaN; a NaN written by a sloppy writer is malformed JSON.
  expectBad(R"({"dims": [2, 2, 2], "type": "u8", "spacing": [NaN, 1, 1]})", 8, {"malformed JSON"});
  expectBad(R"({"dims": [2, 2, 2], "type": "u8", "spacing": [1, 1, 1e999]})", 8,
            {"malformed JSON", "number overflow"});
  expectBad(R"({"dims": [2, 2, 2], "type": "u8", "spacing": ["nan", 1, 1]})", 8,
            {"spacing[0] is \"nan\", expected a number"});
  expectBad(R"({"dims": [2, 2, 2], "type": "u8", "spacing": [1, 0, 1]})", 8,
            {"spacing[1] is 0, expected a finite value > 0"});
  expectBad(R"({"dims": [2, 2, 2], "type": "u8", "spacing": [1, 1, -0.5]})", 8,
            {"spacing[2] is -0.5"});
  expectBad(R"({"dims": [2, 2, 2], "type": "u8", "spacing": [1, 1]})", 8,
            {"spacing is [1,1], expected an array of 3 numbers"});
}

TEST_F(RawSidecarRejects, BadDims) {
  expectBad(R"({"dims": [2, 0, 2], "type": "u8"})", 8, {"dims[1] is 0, expected 1..1048576"});
  expectBad(R"({"dims": [2, 2, -2], "type": "u8"})", 8, {"dims[2] is -2"});
  expectBad(R"({"dims": [2147483648, 1, 1], "type": "u8"})", 8, {"dims[0] is 2147483648"});
  expectBad(R"({"dims": [2.5, 2, 2], "type": "u8"})", 8, {"dims[0] is 2.5, expected a whole"});
  expectBad(R"({"dims": [2, 2], "type": "u8"})", 8, {"dims is [2,2]"});
  expectBad(R"({"type": "u8"})", 8, {"no \"dims\""});
}

TEST_F(RawSidecarRejects, BadEndianOffsetAndOrigin) {
  expectBad(R"({"dims": [2, 2, 2], "type": "u8", "endian": "middle"})", 8,
            {"endian is \"middle\""});
  expectBad(R"({"dims": [2, 2, 2], "type": "u8", "offset": -4})", 8, {"offset is -4"});
  expectBad(R"({"dims": [2, 2, 2], "type": "u8", "origin": [0, null, 0]})", 8,
            {"origin[1] is null"});
}

TEST_F(RawSidecarRejects, DirectionsThatAreNotThreeIndependentUnitVectors) {
  expectBad(R"({"dims": [2, 2, 2], "type": "u8", "direction": [[1, 0, 0], [0, 1, 0]]})", 8,
            {"direction is [[1,0,0],[0,1,0]], expected 3 unit vectors"});
  expectBad(R"({"dims": [2, 2, 2], "type": "u8", "direction": [[2, 0, 0], [0, 1, 0], [0, 0, 1]]})",
            8, {"direction[0] has length 2, expected a unit vector", "\"spacing\""});
  expectBad(R"({"dims": [2, 2, 2], "type": "u8", "direction": [[1, 0, 0], [1, 0, 0], [0, 0, 1]]})",
            8, {"direction: index axes' directions are (nearly) parallel"});
  expectBad(
      R"({"dims": [2, 2, 2], "type": "u8", "direction": [[1, 0, 0], [0, 1, 0], [0, "z", 1]]})", 8,
      {"direction[2][1] is \"z\", expected a number"});
}

TEST_F(RawSidecarRejects, SidecarNamingAnotherFile) {
  writeFile(dir_ / "a.raw", std::string(8, 'a'));
  writeFile(dir_ / "b.raw", std::string(8, 'b'));
  writeFile(dir_ / "a.raw.json", R"({"dims": [2, 2, 2], "type": "u8", "file": "b.raw"})");
  expectRejected<InputError>([&] { readRawWithSidecar(dir_ / "a.raw"); },
                             {"a.raw.json", "\"b.raw\"", "not"});
}

TEST_F(RawSidecarRejects, HugeSidecar) {
  writeFile(dir_ / "data.raw", "x");
  writeFile(dir_ / "data.raw.json", std::string(2 << 20, ' '));
  expectRejected<InputError>([&] { readRawWithSidecar(dir_ / "data.raw"); },
                             {"data.raw.json", "too large for a JSON sidecar"});
}

}  // namespace
}  // namespace tessera
