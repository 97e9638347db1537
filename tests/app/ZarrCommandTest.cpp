// The OME-Zarr options of the CLI: convert writes a store with the chunk,
// level count and compressor asked for (and streams store to store), info
// lists its levels and world frame, render reads the finest level that
// fits the host budget and says which, and --time/--channel are checked.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>

#include <nlohmann/json.hpp>

#include "support/CliRunner.h"
#include "support/TestSupport.h"
#include "tessera/io/VolumeReader.h"

namespace {

using tessera::test::runCli;
using tessera::test::TempDir;

nlohmann::json zarray(const std::filesystem::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

TEST(ZarrCommand, ConvertWritesTheStoreAskedForAndInfoListsIt) {
  const TempDir tmp;
  const auto store = tmp / "p.ome.zarr";
  const auto r = runCli("convert gen:shepp-logan:150x140x130 " + store.string() +
                        " --chunk 128 --levels 2 --compressor blosc");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("2 levels (150x140x130, 75x70x65)"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("convert ["), std::string::npos) << "no progress bar: " << r.err;
  const auto a0 = zarray(store / "0" / ".zarray");
  EXPECT_EQ(a0["chunks"], nlohmann::json({128, 128, 128}));
  EXPECT_EQ(a0["shape"], nlohmann::json({130, 140, 150}));
  EXPECT_EQ(a0["compressor"]["id"], "blosc");
  EXPECT_EQ(zarray(store / "1" / ".zarray")["chunks"], nlohmann::json({65, 70, 75}));
  EXPECT_FALSE(std::filesystem::exists(store / "2"));

  const auto info = runCli("info " + store.string() + " --json");
  ASSERT_EQ(info.exitCode, 0) << info.err;
  const auto j = nlohmann::json::parse(info.out);
  EXPECT_EQ(j["dims"], nlohmann::json({150, 140, 130}));
  EXPECT_EQ(j["zarr"]["levels"].size(), 2u);
  EXPECT_EQ(j["zarr"]["levels"][1]["dims"], nlohmann::json({75, 70, 65}));
  EXPECT_NE(j["geometry_source"].get<std::string>().find("R,A,S"), std::string::npos);
  // Voxels equal the generator's.
  const auto back =
      runCli("convert " + store.string() + " " + (tmp / "b.nrrd").string() + " --quiet");
  ASSERT_EQ(back.exitCode, 0) << back.err;
  const tessera::Volume a = tessera::readVolume("gen:shepp-logan:150x140x130");
  const tessera::Volume b = tessera::readVolume((tmp / "b.nrrd").string());
  ASSERT_EQ(a.byteSize(), b.byteSize());
  EXPECT_TRUE(std::equal(a.bytes().begin(), a.bytes().end(), b.bytes().begin()));
}

TEST(ZarrCommand, StoreToStoreStreamsAndRenderPicksTheLevelThatFits) {
  const TempDir tmp;
  const auto src = tmp / "s.ome.zarr";
  ASSERT_EQ(runCli("convert gen:sphere:200 " + src.string() + " --quiet").exitCode, 0);
  const auto out = tmp / "t.ome.zarr";
  const auto r = runCli("convert " + src.string() + " " + out.string() + " --compressor zlib");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("streaming 200x200x200"), std::string::npos) << r.err;
  EXPECT_EQ(zarray(out / "0" / ".zarray")["compressor"]["id"], "zlib");
  // 200^3 u8 = 7.6 MiB does not fit 6 MiB; level 1 (100^3, 1 MiB) does.
  const auto render =
      runCli("render " + out.string() + " --size 64x64 --out " + (tmp / "r.png").string());
  ASSERT_EQ(render.exitCode, 0) << render.err;
  EXPECT_NE(render.err.find("read level 0 (200x200x200)"), std::string::npos) << render.err;
  setenv("TESSERA_HOST_BUDGET_MB", "6", 1);
  const auto small =
      runCli("render " + out.string() + " --size 64x64 --out " + (tmp / "r.png").string());
  unsetenv("TESSERA_HOST_BUDGET_MB");
  ASSERT_EQ(small.exitCode, 0) << small.err;
  EXPECT_NE(small.err.find("read level 1 (100x100x100) of 3: the finest that fits"),
            std::string::npos)
      << small.err;
}

TEST(ZarrCommand, BadOptionsAreRefusedBeforeReading) {
  const TempDir tmp;
  const auto out = (tmp / "o.ome.zarr").string();
  for (const std::string args :
       {"--chunk 32", "--levels 0", "--levels many", "--compressor lzma"}) {
    const auto r = runCli("convert gen:sphere:16 " + out + " " + args + " --quiet");
    EXPECT_EQ(r.exitCode, 1) << args;
    EXPECT_NE(r.err.find(args.substr(0, args.find(' '))), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << args;
  }
  const auto t = runCli("info gen:sphere:16 --time 1");
  EXPECT_EQ(t.exitCode, 1);
  EXPECT_NE(t.err.find("--time/--channel"), std::string::npos) << t.err;
}

}  // namespace
