// bench/peers is a benchmark, never timed here; its
// --smoke mode checks in seconds that the script draws the same picture as
// VTK's two mappers (a 40^3 LAS volume with an off-centre block, 96x80) and
// writes its table, and that a framing mistake is caught by the PSNR.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "support/CliRunner.h"
#include "support/TestSupport.h"

namespace {

const std::string kScript = std::string(TESSERA_TEST_DATA_DIR) + "/../../bench/peers/peers.py";

bool haveVtk() {
  return std::system(
             "/usr/bin/python3 -c 'import vtk, nibabel, matplotlib' 2>/dev/null && "
             "command -v xvfb-run >/dev/null") == 0;
}

int runSmoke(const tessera::test::TempDir& dir, const std::string& tesseraArgs) {
  const std::string cmd = "/usr/bin/python3 " + kScript + " --smoke --tessera " + TESSERA_CLI_PATH +
                          " --out " + dir.path().string() +
                          (tesseraArgs.empty() ? "" : " --tessera-args '" + tesseraArgs + "'") +
                          " >" + (dir / "log.txt").string() + " 2>&1";
  return std::system(cmd.c_str());
}

}  // namespace

TEST(PeersBench, SmokeRunDrawsVtksPictureAndWritesTheTable) {
  if (!haveVtk()) GTEST_SKIP() << "python3-vtk9 / xvfb not installed (scripts/setup.sh)";
  tessera::test::TempDir dir;
  ASSERT_EQ(runSmoke(dir, ""), 0) << std::ifstream(dir / "log.txt").rdbuf();
  std::ifstream in(dir / "peers.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["rows"].size(), 1u);
  const nlohmann::json& row = j["rows"][0];
  EXPECT_GE(row["psnr_vs_vtk-cpu"].get<double>(), 30.0);
  EXPECT_GE(row["psnr_vs_vtk-gpu"].get<double>(), 30.0);
  EXPECT_GE(row["footprint_iou_vs_vtk-cpu"].get<double>(), 0.9);
  for (const char* r : {"tessera", "vtk-cpu", "vtk-gpu"}) {
    EXPECT_EQ(row[std::string(r) + "_frame_ms"].size(), 2u) << r;
  }
  EXPECT_TRUE(std::filesystem::exists(dir / "peers.md"));
  EXPECT_TRUE(std::filesystem::exists(dir / "peers.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "peers.png"));
}

TEST(PeersBench, SmokeRunFailsWhenTheFramingDiffers) {
  if (!haveVtk()) GTEST_SKIP() << "python3-vtk9 / xvfb not installed (scripts/setup.sh)";
  tessera::test::TempDir dir;
  EXPECT_NE(runSmoke(dir, "--zoom 1.15"), 0) << std::ifstream(dir / "log.txt").rdbuf();
}

// `tessera bench --peers` runs the same script with this binary as Tessera.
TEST(PeersBench, TheCliRunsTheScriptWithItself) {
  if (!haveVtk()) GTEST_SKIP() << "python3-vtk9 / xvfb not installed (scripts/setup.sh)";
  tessera::test::TempDir dir;
  const auto run = tessera::test::runCli("bench --peers --peers-args=\"--smoke --out " +
                                         dir.path().string() + "\"");
  ASSERT_EQ(run.exitCode, 0) << (run.out + run.err);
  EXPECT_NE((run.out + run.err).find(std::string("--tessera ") + TESSERA_CLI_PATH),
            std::string::npos)
      << (run.out + run.err);
  std::ifstream in(dir / "peers.json");
  ASSERT_TRUE(in.good()) << (run.out + run.err);
  EXPECT_FALSE(nlohmann::json::parse(in)["rows"].empty());
}

// Without the source tree (or with a wrong one) the error names the path.
TEST(PeersBench, TheCliNamesAMissingScript) {
  tessera::test::TempDir dir;
  for (const std::string flag : {"--peers", "--web-peers"}) {
    const auto run =
        tessera::test::runCli("bench " + flag + " --source-dir " + dir.path().string());
    EXPECT_EQ(run.exitCode, 1) << (run.out + run.err);
    EXPECT_NE((run.out + run.err).find(dir.path().string() + "/bench/"), std::string::npos)
        << (run.out + run.err);
    EXPECT_NE((run.out + run.err).find("not found"), std::string::npos) << (run.out + run.err);
  }
  const auto both = tessera::test::runCli("bench --peers --web-peers");
  EXPECT_EQ(both.exitCode, 1);
  EXPECT_NE(both.err.find("one at a time"), std::string::npos) << both.err;
}
