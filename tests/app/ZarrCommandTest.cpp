// The OME-Zarr options of the CLI: convert writes a store with the chunk,
// level count and compressor asked for (and streams store to store), info
// lists its levels and world frame, render reads the finest level that
// fits the host budget and says which, and --time/--channel are checked.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>

#include <nlohmann/json.hpp>

#include "io/ZarrTestSupport.h"
#include "support/CliRunner.h"
#include "support/TestSupport.h"
#include "tessera/core/Image.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/reference/ImageMetrics.h"

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
  const auto render =
      runCli("render " + out.string() + " --size 64x64 --out " + (tmp / "r.png").string());
  ASSERT_EQ(render.exitCode, 0) << render.err;
  EXPECT_NE(render.err.find("read level 0 (200x200x200)"), std::string::npos) << render.err;
  // 200^3 u8 = 7.6 MiB does not fit 6 MiB: render streams it through bricks;
  // an option that needs the voxels in core (here --labels) reads level 1
  // (100^3, 1 MiB), the finest that fits.
  setenv("TESSERA_HOST_BUDGET_MB", "6", 1);
  const auto streamed =
      runCli("render " + out.string() + " --size 64x64 --out " + (tmp / "r.png").string());
  const auto small =
      runCli("render " + out.string() + " --size 64x64 --labels --out " + (tmp / "r.png").string());
  // A window streams like the default one (the bricks see it).
  const auto windowed = runCli("render " + out.string() + " --size 64x64 --window 0 200 --out " +
                               (tmp / "w.png").string());
  unsetenv("TESSERA_HOST_BUDGET_MB");
  ASSERT_EQ(windowed.exitCode, 0) << windowed.err;
  EXPECT_NE(windowed.out.find("layout   bricks:"), std::string::npos) << windowed.out;
  ASSERT_EQ(streamed.exitCode, 0) << streamed.err;
  EXPECT_NE(streamed.out.find("layout   bricks:"), std::string::npos) << streamed.out;
  EXPECT_NE(streamed.out.find("needs 7.6 MiB of host memory in core, over the host budget 6 MiB"),
            std::string::npos)
      << streamed.out;
  ASSERT_EQ(small.exitCode, 0) << small.err;
  EXPECT_NE(small.err.find("read level 1 (100x100x100) of 3: the finest that fits"),
            std::string::npos)
      << small.err;
}

// --layout auto: a store whose finest level does not fit the profile's host
// budget streams through bricks at full resolution, and its image equals the
// in-core texture3d render of the same store at a generous budget.
TEST(ZarrCommand, AutoStreamsAStoreThatDoesNotFitAndMatchesTheInCoreRender) {
  const TempDir tmp;
  const auto store = tmp / "s.ome.zarr";
  ASSERT_EQ(runCli("convert gen:shepp-logan:160 " + store.string() + " --quiet").exitCode, 0);
  // 160^3 u8 = 3.9 MiB in core; 3 MiB of host, 16 MiB of textures.
  const auto profile = tmp / "tight.json";
  std::ofstream(profile) << R"({"name": "tight", "note": "test", "api": "gles3",
                               "max_2d_texture_size": 4096, "max_3d_texture_size": 2048,
                               "texture_units": 8, "texture_budget_mb": 16,
                               "host_budget_mb": 3})";
  const std::string view = " --size 256x256 --azimuth 30 --elevation 20 --json";
  const auto tight = runCli("render " + store.string() + view + " --profile " + profile.string() +
                            " --out " + (tmp / "tight.png").string());
  ASSERT_EQ(tight.exitCode, 0) << tight.err;
  const auto jt = nlohmann::json::parse(tight.out);
  EXPECT_EQ(jt["layout"], "bricks");
  EXPECT_NE(jt["plan_reason"].get<std::string>().find("over the host budget 3 MiB of tight"),
            std::string::npos)
      << jt["plan_reason"];
  EXPECT_TRUE(jt["bricks"]["complete"].get<bool>());
  // At 256^2 a level-0 voxel covers about a pixel: every wanted brick is L0.
  const auto wanted = jt["bricks"]["wanted_per_level"];
  ASSERT_FALSE(wanted.empty());
  EXPECT_GT(wanted[0].get<int>(), 0) << wanted;
  for (std::size_t l = 1; l < wanted.size(); ++l) EXPECT_EQ(wanted[l], 0) << wanted;

  const auto roomy =
      runCli("render " + store.string() + view + " --out " + (tmp / "roomy.png").string());
  ASSERT_EQ(roomy.exitCode, 0) << roomy.err;
  EXPECT_EQ(nlohmann::json::parse(roomy.out)["layout"], "texture3d");
  const double db = tessera::psnr(tessera::Image::readPng(tmp / "tight.png"),
                                  tessera::Image::readPng(tmp / "roomy.png"));
  std::printf("streamed vs in-core: %.1f dB\n", db);
  EXPECT_GE(db, 45.0);
}

std::uint64_t filesBytes(const std::filesystem::path& folder) {
  std::uint64_t bytes = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(folder)) {
    if (e.is_regular_file()) bytes += e.file_size();
  }
  return bytes;
}

// The bricked render of a store served by nginx (started here on a free
// port of 127.0.0.1) equals the bricked render of the same folder, and
// fetches only the chunks the view wants: fewer bytes than the finest
// level's chunks.
TEST(ZarrCommand, BricksOverHttpEqualTheFolderAndFetchLessThanTheFinestLevel) {
  if (!std::filesystem::exists(tessera::test::Nginx::kBinary)) {
    GTEST_SKIP() << "nginx not installed (nginx-light)";
  }
  const TempDir tmp;
  const auto store = tmp / "www" / "store.ome.zarr";
  std::filesystem::create_directories(tmp / "www");
  // Marschner-Lobb (f32, smooth: every level compresses alike, unlike the
  // piecewise-constant phantom whose finest level zstd shrinks the most).
  ASSERT_EQ(runCli("convert gen:marschner-lobb:160 " + store.string() + " --quiet").exitCode, 0);
  const tessera::test::Nginx nginx(tmp / "www", tmp / "nginx");
  const std::string view = " --layout bricks --size 96x96 --azimuth 30 --elevation 20 --json";
  const auto local =
      runCli("render " + store.string() + view + " --out " + (tmp / "local.png").string());
  ASSERT_EQ(local.exitCode, 0) << local.err;
  const auto remote = runCli("render " + nginx.url("store.ome.zarr") + view + " --out " +
                             (tmp / "remote.png").string());
  ASSERT_EQ(remote.exitCode, 0) << remote.err;
  const auto jl = nlohmann::json::parse(local.out);
  const auto jr = nlohmann::json::parse(remote.out);
  EXPECT_EQ(jr["layout"], "bricks");
  EXPECT_TRUE(jr["bricks"]["complete"].get<bool>());
  EXPECT_EQ(jr["bricks"]["wanted_per_level"], jl["bricks"]["wanted_per_level"]);
  EXPECT_FALSE(jl.contains("http"));  // a folder is not fetched
  const double db = tessera::psnr(tessera::Image::readPng(tmp / "local.png"),
                                  tessera::Image::readPng(tmp / "remote.png"));
  EXPECT_GE(db, 60.0);
  const std::uint64_t fetched = jr["http"]["bytes_fetched"].get<std::uint64_t>();
  const std::uint64_t finest = filesBytes(store / "0");
  std::printf("http vs folder: %.1f dB; fetched %llu bytes in %llu requests, level 0 holds %llu\n",
              db, static_cast<unsigned long long>(fetched),
              static_cast<unsigned long long>(jr["http"]["requests"].get<std::uint64_t>()),
              static_cast<unsigned long long>(finest));
  EXPECT_GT(fetched, 0u);
  EXPECT_LT(fetched, finest);
}

// Microscopy stores chunk z thinner than y and x: --chunk Z,Y,X.
TEST(ZarrCommand, ConvertWritesPerAxisChunks) {
  const TempDir tmp;
  const auto store = tmp / "m.ome.zarr";
  const auto r =
      runCli("convert gen:shepp-logan:100x90x40 " + store.string() + " --chunk 16,32,64 --quiet");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("3 levels (100x90x40, 50x45x20, 25x23x10), chunks 16,32,64 (z,y,x)"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(zarray(store / "0" / ".zarray")["chunks"], nlohmann::json({16, 32, 64}));
  EXPECT_EQ(zarray(store / "2" / ".zarray")["chunks"], nlohmann::json({10, 23, 25}));
  const auto back =
      runCli("convert " + store.string() + " " + (tmp / "b.nrrd").string() + " --quiet");
  ASSERT_EQ(back.exitCode, 0) << back.err;
  const tessera::Volume a = tessera::readVolume("gen:shepp-logan:100x90x40");
  const tessera::Volume b = tessera::readVolume((tmp / "b.nrrd").string());
  ASSERT_EQ(a.byteSize(), b.byteSize());
  EXPECT_TRUE(std::equal(a.bytes().begin(), a.bytes().end(), b.bytes().begin()));
}

TEST(ZarrCommand, BadOptionsAreRefusedBeforeReading) {
  const TempDir tmp;
  const auto out = (tmp / "o.ome.zarr").string();
  for (const std::string args :
       {"--chunk 32", "--chunk 32,512", "--chunk 7,512,512", "--chunk 32,512,512,8", "--levels 0",
        "--levels many", "--compressor lzma"}) {
    const auto r = runCli("convert gen:sphere:16 " + out + " " + args + " --quiet");
    EXPECT_EQ(r.exitCode, 1) << args;
    EXPECT_NE(r.err.find(args.substr(0, args.find(' '))), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << args;
  }
  const auto t = runCli("info gen:sphere:16 --time 1");
  EXPECT_EQ(t.exitCode, 1);
  EXPECT_NE(t.err.find("gen:sphere:16: --time selects a time point of an OME-Zarr store or a "
                       "4-D NIfTI file; this is neither"),
            std::string::npos)
      << t.err;
  const auto c = runCli("info gen:sphere:16 --channel 1");
  EXPECT_EQ(c.exitCode, 1);
  EXPECT_NE(c.err.find("gen:sphere:16: --channel selects within an OME-Zarr store"),
            std::string::npos)
      << c.err;
}

}  // namespace
