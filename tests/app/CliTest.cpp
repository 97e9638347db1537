// The `tessera` executable as users and scripts see it: exit codes, one-line
// errors, JSON fields, and the PNG it writes.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "support/CliRunner.h"
#include "support/TestSupport.h"
#include "tessera/core/Image.h"

namespace fs = std::filesystem;

namespace {

using tessera::test::CliRun;
using tessera::test::countLines;

// stdout and stderr together, as a user sees them.
CliRun run(const std::string& args) {
  CliRun r = tessera::test::runCli(args);
  r.out += r.err;
  return r;
}

}  // namespace

// The default sampling (docs/sampling.md, "Defaults"): post-classified
// adaptive steps, tolerance 0.5 unlit and 0.25 lit; --preintegrate on, lit
// (only lit frames) and off; a given --adaptive-tolerance holds for both.
TEST(Cli, RenderSamplesPostClassifiedByDefaultWithAHalvedToleranceWhenLit) {
  const tessera::test::TempDir tmp;
  const std::string out = " --out " + (tmp / "p.png").string();
  const auto report = [&](const std::string& extra) {
    const CliRun r = run("render gen:shepp-logan:32 --size 32x32 --json --tf bench " + extra + out);
    EXPECT_EQ(r.exitCode, 0) << r.out;
    return nlohmann::json::parse(r.out);
  };
  auto j = report("");
  EXPECT_FALSE(j["preintegrate"].get<bool>());
  EXPECT_DOUBLE_EQ(j["adaptive_tolerance"].get<double>(), 0.5);
  j = report("--shade");
  EXPECT_FALSE(j["preintegrate"].get<bool>());
  EXPECT_DOUBLE_EQ(j["adaptive_tolerance"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(report("--gradient-opacity on")["adaptive_tolerance"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(report("--shade --adaptive-tolerance 0.4")["adaptive_tolerance"].get<double>(),
                   0.4);
  EXPECT_TRUE(report("--preintegrate on")["preintegrate"].get<bool>());
  EXPECT_FALSE(report("--preintegrate lit")["preintegrate"].get<bool>());
  EXPECT_TRUE(report("--shade --preintegrate lit")["preintegrate"].get<bool>());
  const CliRun bad = run("render gen:shepp-logan:32 --size 32x32 --preintegrate maybe" + out);
  EXPECT_NE(bad.exitCode, 0);
  EXPECT_NE(bad.out.find("--preintegrate 'maybe': expected on, off or lit"), std::string::npos)
      << bad.out;
}

TEST(Cli, RenderPhantomJsonReportsRequiredFieldsAndWritesPng) {
  const tessera::test::TempDir tmp;
  const fs::path png = tmp / "phantom.png";
  const CliRun r =
      run("render gen:shepp-logan:48 --size 64x48 --repeat 3 --rotate 10 --reference --json --tf "
          "bench --out " +
          png.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key : {"ms_median", "ms_min", "ms_max", "frames", "psnr_db", "ssim",
                          "texture_bytes", "gl_renderer", "width", "height"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["frames"], 3);
  EXPECT_EQ(j["width"], 64);
  EXPECT_EQ(j["height"], 48);
  EXPECT_LE(j["ms_min"].get<double>(), j["ms_median"].get<double>());
  EXPECT_LE(j["ms_median"].get<double>(), j["ms_max"].get<double>());
  EXPECT_GE(j["psnr_db"].get<double>(), 40.0);
  // 48^3 u8 volume + the 4096-entry RGBA16F TF table (unlit frames are
  // post-classified by default) + 6^3 RGBA8 blocks + 64x48 RGBA8 target + VBO.
  EXPECT_EQ(j["texture_bytes"].get<std::uint64_t>(),
            48u * 48 * 48 + 4096u * 8 + 6u * 6 * 6 * 4 + 64u * 48 * 4 + 24u);
  EXPECT_EQ(j["preintegrate"], false);
  EXPECT_EQ(j["adaptive"], true);
  EXPECT_GT(j["samples_per_ray"].get<double>(), 0.0);
  const tessera::Image img = tessera::Image::readPng(png);
  EXPECT_EQ(img.width(), 64);
  EXPECT_EQ(img.height(), 48);
}

TEST(Cli, MissingFileFailsWithOneLineError) {
  const CliRun r = run("render /nonexistent/volume.nii.gz --out /tmp/none.png");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_EQ(countLines(r.out), 1) << r.out;
  EXPECT_NE(r.out.find("/nonexistent/volume.nii.gz"), std::string::npos) << r.out;
}

TEST(Cli, TruncatedNiftiFailsFastWithClearError) {
  const tessera::test::TempDir tmp;
  const fs::path& dir = tmp.path();
  // A NIfTI-1 header claiming 512^3 int16 voxels, followed by only 1 KiB.
  std::vector<char> bytes(352 + 1024, 0);
  auto put32 = [&](std::size_t off, std::int32_t v) { std::memcpy(&bytes[off], &v, 4); };
  auto put16 = [&](std::size_t off, std::int16_t v) { std::memcpy(&bytes[off], &v, 2); };
  auto putF = [&](std::size_t off, float v) { std::memcpy(&bytes[off], &v, 4); };
  put32(0, 348);
  put16(40, 3);
  put16(42, 512);
  put16(44, 512);
  put16(46, 512);
  put16(48, 1);
  put16(70, 4);   // DT_INT16
  put16(72, 16);  // bitpix
  putF(76, 1.0f);
  putF(80, 1.0f);
  putF(84, 1.0f);
  putF(88, 1.0f);
  putF(108, 352.0f);  // vox_offset
  std::memcpy(&bytes[344], "n+1\0", 4);
  const fs::path f = dir / "truncated.nii";
  std::ofstream(f, std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  const CliRun r = run("render " + f.string() + " --out " + (dir / "t.png").string());
  EXPECT_NE(r.exitCode, 0);
  EXPECT_EQ(countLines(r.out), 1) << r.out;
  EXPECT_NE(r.out.find(f.string()), std::string::npos) << r.out;
  // A guard against hangs, not a speed test: the wall time of a whole process
  // (GL start-up included, and ASan's under `scripts/sanitize.sh` on a busy
  // machine) is no measure of the reader. Refusal within a second and without
  // large allocations is measured in-process for every corpus file
  // (io/BadCorpusTest.cpp); the command itself takes ~0.1 s here.
  EXPECT_LT(r.seconds, 15.0);
  EXPECT_FALSE(fs::exists(dir / "t.png"));
  const CliRun info = run("info " + f.string());
  EXPECT_NE(info.exitCode, 0);
}

TEST(Cli, BadOptionsAreRejected) {
  EXPECT_NE(run("render gen:sphere:16 --size 12by12").exitCode, 0);
  EXPECT_NE(run("render gen:sphere:16 --mode xray").exitCode, 0);
  EXPECT_NE(run("render gen:sphere:16 --tf no-such-preset").exitCode, 0);
  EXPECT_NE(run("render gen:sphere:16 --step 0").exitCode, 0);
  EXPECT_NE(run("render gen:sphere:16 --window 5 5").exitCode, 0);
  EXPECT_NE(run("").exitCode, 0);
  for (const char* args : {"render gen:sphere:16 --mode", "render --size 12by12", "nonsense"}) {
    const CliRun r = run(args);
    EXPECT_NE(r.exitCode, 0) << args;
    EXPECT_EQ(countLines(r.out), 1) << args << ": " << r.out;
    EXPECT_EQ(r.out.rfind("tessera: error: ", 0), 0u) << r.out;
  }
  const CliRun help = run("render --help");
  EXPECT_EQ(help.exitCode, 0);
  EXPECT_NE(help.out.find("--reference"), std::string::npos);
}

TEST(Cli, InfoPrintsDimsSpacingAndType) {
  const CliRun r = run("info gen:shepp-logan:32x24x16 --json");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["dims"], nlohmann::json({32, 24, 16}));
  EXPECT_EQ(j["type"], "u8");
  EXPECT_EQ(j["bytes"], 32 * 24 * 16);
}
