// Interoperability is the acceptance: stores zarr-python writes
// (blosc lz4/zstd with shuffle/bitshuffle, zlib, gzip, zstd, none; "/" and
// "." separators; u1, <u2, >i2, <f4, <i4; missing chunks; chunks that do
// not divide the shape; 5D t,c,z,y,x) are read voxel-exact, and stores
// Tessera writes are read by zarr-python voxel-exact with the right NGFF
// multiscales metadata (tests/zarr/check_store.py).
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "io/ZarrTestSupport.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/io/ZarrStore.h"
#include "tessera/io/ZarrWriter.h"

namespace tessera {
namespace {

using test::TempDir;

ReadOptions select(int time, int channel) {
  ReadOptions o;
  o.time = time;
  o.channel = channel;
  return o;
}

std::vector<char> fileBytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

class ZarrInterop : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!test::zarrPythonMissing().empty()) return;
    dir_ = new TempDir();
    const std::string cmd = std::string(test::kZarrPython) + " " +
                            test::zarrScript("make_stores.py").string() + " " +
                            dir_->path().string();
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    std::ifstream in(dir_->path() / "cases.json");
    cases_ = nlohmann::json::parse(in);
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override {
    if (const std::string why = test::zarrPythonMissing(); !why.empty()) GTEST_SKIP() << why;
  }
  static TempDir* dir_;
  static nlohmann::json cases_;
};
TempDir* ZarrInterop::dir_ = nullptr;
nlohmann::json ZarrInterop::cases_;

TEST_F(ZarrInterop, ReadsZarrPythonStoresVoxelExact) {
  ASSERT_EQ(cases_.size(), 6u);
  for (const auto& c : cases_) {
    SCOPED_TRACE(c["name"].get<std::string>());
    const std::string store = c["store"];
    const Volume v = readVolume(store, select(c["time"], c["channel"]));
    EXPECT_EQ(v.dims(), glm::ivec3(c["dims"][0], c["dims"][1], c["dims"][2]));
    EXPECT_EQ(std::string(scalarTypeName(v.type())), c["type"].get<std::string>());
    for (int a = 0; a < 3; ++a) {
      EXPECT_DOUBLE_EQ(v.spacing()[a], c["spacing"][std::size_t(a)].get<double>());
      EXPECT_DOUBLE_EQ(v.origin()[a], c["origin"][std::size_t(a)].get<double>());
    }
    const std::vector<char> want = fileBytes(c["expected"].get<std::string>());
    ASSERT_EQ(v.byteSize(), want.size());
    // Bitwise: NaN fill of missing chunks included.
    EXPECT_EQ(std::memcmp(v.bytes().data(), want.data(), want.size()), 0);
    const ZarrStore z(openZarrStorage(store), {.time = c["time"], .channel = c["channel"]});
    EXPECT_EQ(z.levelCount(), c["levels"].get<int>());
    if (!c["note"].get<std::string>().empty()) {
      ASSERT_FALSE(z.notes().empty());
      EXPECT_NE(z.notes().back().find(c["note"].get<std::string>()), std::string::npos);
    }
    // A box across chunk borders reads the same voxels as the whole level.
    const glm::ivec3 d = v.dims();
    const glm::ivec3 lo = d / 4, hi = d - d / 5;
    const Volume box = z.readBox(0, lo, hi);
    ASSERT_EQ(box.dims(), hi - lo);
    const std::size_t bpv = bytesPerVoxel(v.type());
    for (int zz = lo.z; zz < hi.z; ++zz) {
      for (int y = lo.y; y < hi.y; ++y) {
        ASSERT_EQ(std::memcmp(box.bytes().data() + box.index(0, y - lo.y, zz - lo.z) * bpv,
                              v.bytes().data() + v.index(lo.x, y, zz) * bpv,
                              std::size_t(hi.x - lo.x) * bpv),
                  0);
      }
    }
    EXPECT_DOUBLE_EQ(box.origin().x, v.worldOf(glm::dvec3(lo)).x);
    EXPECT_DOUBLE_EQ(box.origin().z, v.worldOf(glm::dvec3(lo)).z);
  }
}

TEST_F(ZarrInterop, SecondLevelIsReadAsWritten) {
  const auto& c = cases_[1];
  ASSERT_EQ(c["name"], "u16_zlib_dot");
  const ZarrStore z(openZarrStorage(c["store"]));
  const Volume fine = z.readLevel(0);
  const Volume coarse = z.readLevel(1);
  ASSERT_EQ(coarse.dims(), (fine.dims() + 1) / 2);
  for (int zz = 0; zz < coarse.dims().z; ++zz) {
    for (int y = 0; y < coarse.dims().y; ++y) {
      for (int x = 0; x < coarse.dims().x; ++x) {
        ASSERT_EQ(coarse.valueAt(x, y, zz), fine.valueAt(2 * x, 2 * y, 2 * zz));
      }
    }
  }
  EXPECT_DOUBLE_EQ(z.level(1).spacing.x, 2.0);
  EXPECT_DOUBLE_EQ(z.level(1).origin.y, 0.5);
}

TEST_F(ZarrInterop, TimeAndChannelOutsideTheStoreAreErrors) {
  const std::string store = cases_[4]["store"];
  try {
    readVolume(store, select(2, 0));
    FAIL() << "--time 2 of 2 time points was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--time 2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(readVolume(store, select(0, 3)), InputError);
  EXPECT_THROW(readVolume(cases_[0]["store"].get<std::string>(), select(1, 0)), InputError);
}

// A store's t axis is a time series as a 4-D NIfTI's is: its length counted,
// each time point (of the channel asked for) read as readVolume reads it;
// stores without a t axis hold one time point.
TEST_F(ZarrInterop, AStoresTimeAxisIsATimeSeries) {
  const std::string store = cases_[4]["store"];
  ASSERT_EQ(cases_[4]["name"], "tczyx_u16_zstd");
  EXPECT_EQ(ZarrStore(openZarrStorage(store)).timePoints(), 2);
  EXPECT_EQ(timePointCount(store), 2);
  for (int t = 0; t < 2; ++t) {
    for (const int c : {0, 2}) {
      const Volume want = readVolume(store, select(t, c));
      const Volume got = readTimePoint(store, t, c);
      ASSERT_EQ(got.byteSize(), want.byteSize());
      EXPECT_EQ(std::memcmp(got.bytes().data(), want.bytes().data(), want.byteSize()), 0)
          << "t " << t << " c " << c;
    }
  }
  EXPECT_NE(
      std::memcmp(readTimePoint(store, 0, 0).bytes().data(),
                  readTimePoint(store, 1, 0).bytes().data(), readTimePoint(store, 0, 0).byteSize()),
      0)
      << "the two time points are the same voxels";
  EXPECT_EQ(timePointCount(cases_[0]["store"].get<std::string>()), 1);
  EXPECT_THROW(readTimePoint(store, 2, 0), InputError);
}

// Tessera's writer, checked by zarr-python: level 0 voxel-exact, every
// level the 2x2x2 mean of the one before, NGFF metadata.
TEST_F(ZarrInterop, ZarrPythonReadsTesseraStoresVoxelExact) {
  struct Case {
    ScalarType type;
    const char* dtype;
    glm::ivec3 dims;
    int chunk;
    ZarrCompressor compressor;
  };
  const Case cases[] = {
      {ScalarType::U8, "<u1", {50, 37, 29}, 16, ZarrCompressor::Zstd},
      {ScalarType::U16, "<u2", {33, 20, 41}, 16, ZarrCompressor::Blosc},
      {ScalarType::I16, "<i2", {19, 24, 17}, 8, ZarrCompressor::Zlib},
      {ScalarType::F32, "<f4", {21, 18, 22}, 16, ZarrCompressor::None},
  };
  const TempDir tmp;
  unsigned seed = 10;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.dtype);
    Volume v = test::randomVolume(c.dims, c.type, seed++, {.withNaN = c.type == ScalarType::F32});
    v.setSpacing({0.5, 0.75, 1.25});
    v.setOrigin({-10.0, 20.0, 3.5});
    const auto store = tmp / (std::string(c.dtype + 1) + ".ome.zarr");
    OmeZarrWriteOptions options;
    options.chunk = c.chunk;
    options.compressor = c.compressor;
    const OmeZarrWriteResult r = writeOmeZarr(v, store, options);
    EXPECT_EQ(r.levelDims.size(), std::size_t(omeZarrAutoLevels(c.dims, c.chunk)));
    EXPECT_LE(r.levelDims.back().x, c.chunk);
    const auto raw = tmp / "source.bin";
    std::ofstream(raw, std::ios::binary)
        .write(reinterpret_cast<const char*>(v.bytes().data()), std::streamsize(v.byteSize()));
    std::ostringstream cmd;
    cmd << test::kZarrPython << " " << test::zarrScript("check_store.py").string() << " "
        << store.string() << " " << raw.string() << " '" << c.dtype << "' " << c.dims.x << " "
        << c.dims.y << " " << c.dims.z << " 0.5 0.75 1.25 -10 20 3.5 2>&1";
    FILE* p = popen(cmd.str().c_str(), "r");
    std::string out;
    char buf[512];
    while (std::fgets(buf, sizeof buf, p)) out += buf;
    EXPECT_EQ(pclose(p), 0) << out;
    EXPECT_NE(out.find("\"problems\": []"), std::string::npos) << out;
    // And Tessera reads its own store back identically.
    const Volume back = readVolume(store.string());
    ASSERT_EQ(back.dims(), v.dims());
    EXPECT_EQ(std::memcmp(back.bytes().data(), v.bytes().data(), v.byteSize()), 0);
    EXPECT_EQ(back.origin(), v.origin());
  }
}

TEST_F(ZarrInterop, RewritingAStoreReplacesItAndRefusesOtherFolders) {
  const TempDir tmp;
  const Volume a = test::randomVolume({20, 20, 20}, ScalarType::U8, 1);
  const Volume b = test::randomVolume({10, 12, 14}, ScalarType::U8, 2);
  writeOmeZarr(a, tmp / "x.ome.zarr");
  writeOmeZarr(b, tmp / "x.ome.zarr");
  EXPECT_EQ(readVolume((tmp / "x.ome.zarr").string()).dims(), b.dims());
  for (const auto& e : std::filesystem::directory_iterator(tmp.path())) {
    EXPECT_EQ(e.path().filename(), "x.ome.zarr") << "left behind: " << e.path();
  }
  std::filesystem::create_directories(tmp / "photos.zarr");
  std::ofstream(tmp / "photos.zarr" / "keep.jpg") << "x";
  EXPECT_THROW(writeOmeZarr(a, tmp / "photos.zarr"), InputError);
  EXPECT_TRUE(std::filesystem::exists(tmp / "photos.zarr" / "keep.jpg"));
}

}  // namespace
}  // namespace tessera
