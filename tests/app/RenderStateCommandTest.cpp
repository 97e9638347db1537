// `tessera render --save-state FILE` and `--state FILE`: a saved render's
// settings come back whole (the same PNG, byte for byte), an option given
// with --state replaces only what it sets, and a bad file fails with one line
// naming the file and the problem.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "support/CliRunner.h"
#include "support/TestSupport.h"

namespace fs = std::filesystem;

namespace {

using tessera::test::CliRun;
using tessera::test::countLines;
using tessera::test::runCli;

// Small, so that each render takes a fraction of a second on llvmpipe.
const std::string kVolume = "render gen:shepp-logan:48 --size 64x48 ";
// Not one of them the default.
std::string settingsAt(int azimuth) {
  return "--azimuth " + std::to_string(azimuth) +
         " --elevation 12 --tf grey --window 10 200 --mode mip --step 0.75 ";
}

std::string bytesOf(const fs::path& file) {
  std::ostringstream bytes;
  bytes << std::ifstream(file, std::ios::binary).rdbuf();
  return bytes.str();
}

nlohmann::json jsonOf(const fs::path& file) {
  return nlohmann::json::parse(bytesOf(file));
}

void writeText(const fs::path& file, const std::string& text) {
  std::ofstream(file, std::ios::binary) << text;
}

CliRun mustRun(const std::string& args) {
  CliRun r = runCli(args);
  EXPECT_EQ(r.exitCode, 0) << args << ": " << r.err;
  return r;
}

// The render of settingsAt(37) and its state, in `dir`.
fs::path saveRender(const fs::path& dir) {
  const fs::path state = dir / "new" / "folder" / "state.json";  // folders made by --save-state
  mustRun(kVolume + settingsAt(37) + "--out " + (dir / "saved.png").string() + " --save-state " +
          state.string());
  return state;
}

// Runs render with --state `file`, which must fail with exit code 1 and the
// one line "tessera: error: --state FILE: <problem>", before anything is
// written.
void expectStateError(const tessera::test::TempDir& tmp, const fs::path& file,
                      const std::string& problem) {
  const fs::path png = tmp / "never.png";
  const CliRun r = runCli(kVolume + "--state " + file.string() + " --out " + png.string());
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(r.err, "tessera: error: --state " + file.string() + ": " + problem + "\n");
  EXPECT_EQ(countLines(r.err), 1) << r.err;
  EXPECT_FALSE(fs::exists(png));
}

}  // namespace

TEST(RenderState, ARenderFromASavedStateIsByteIdenticalToTheRenderThatSavedIt) {
  const tessera::test::TempDir tmp;
  const fs::path state = saveRender(tmp.path());
  mustRun(kVolume + "--state " + state.string() + " --out " + (tmp / "restored.png").string());
  mustRun(kVolume + "--out " + (tmp / "plain.png").string());

  const std::string saved = bytesOf(tmp / "saved.png");
  ASSERT_GT(saved.size(), 100u);
  // Compared as a whole (gtest would print the PNGs' bytes).
  EXPECT_TRUE(bytesOf(tmp / "restored.png") == saved);
  // The settings made a difference, so the equality above measures them.
  EXPECT_TRUE(bytesOf(tmp / "plain.png") != saved);
}

TEST(RenderState, TheSavedStateHoldsTheRendersSettingsAndVolume) {
  const tessera::test::TempDir tmp;
  const nlohmann::json j = jsonOf(saveRender(tmp.path()));
  EXPECT_EQ(j["version"], 1);
  EXPECT_EQ(j["volume"]["name"], "gen:shepp-logan:48");
  EXPECT_EQ(j["volume"]["dims"], nlohmann::json({48, 48, 48}));
  const nlohmann::json& s = j["settings"];
  EXPECT_EQ(s["camera"]["azimuth"], 37.0);
  EXPECT_EQ(s["camera"]["elevation"], 12.0);
  EXPECT_EQ(s["tf"]["name"], "grey");
  EXPECT_EQ(s["window"], nlohmann::json({10.0, 200.0}));
  EXPECT_EQ(s["mode"], "mip");
  EXPECT_EQ(s["step"], 0.75);
}

// --state with --azimuth 90: the file's mode, TF, window and step, the
// option's azimuth; the same image as all of them given as options.
TEST(RenderState, AnOptionGivenWithStateReplacesOnlyWhatItSets) {
  const tessera::test::TempDir tmp;
  const fs::path state = saveRender(tmp.path());
  const fs::path resaved = tmp / "resaved.json";
  const CliRun r = mustRun(kVolume + "--state " + state.string() + " --azimuth 90 --json --out " +
                           (tmp / "turned.png").string() + " --save-state " + resaved.string());
  const nlohmann::json report = nlohmann::json::parse(r.out);
  EXPECT_EQ(report["mode"], "mip");
  EXPECT_EQ(report["tf"], "grey");
  EXPECT_EQ(report["step_voxels"], 0.75);

  const nlohmann::json s = jsonOf(resaved)["settings"];
  EXPECT_EQ(s["camera"]["azimuth"], 90.0);
  EXPECT_EQ(s["camera"]["elevation"], 12.0);
  EXPECT_EQ(s["window"], nlohmann::json({10.0, 200.0}));

  mustRun(kVolume + settingsAt(90) + "--out " + (tmp / "options.png").string());
  const std::string turned = bytesOf(tmp / "turned.png");
  ASSERT_GT(turned.size(), 100u);
  EXPECT_TRUE(turned == bytesOf(tmp / "options.png"));
  EXPECT_TRUE(turned != bytesOf(tmp / "saved.png"));
}

TEST(RenderState, AMissingFileOrAFolderIsNamed) {
  const tessera::test::TempDir tmp;
  expectStateError(tmp, tmp / "absent.json", "cannot open: No such file or directory");
  expectStateError(tmp, tmp.path(), "a folder, not a file");
}

TEST(RenderState, AFileThatIsNotJsonIsNamed) {
  const tessera::test::TempDir tmp;
  writeText(tmp / "state.json", "{\"version\": 1, settings}");
  expectStateError(tmp, tmp / "state.json", "not JSON (syntax error at byte 16)");
}

TEST(RenderState, JsonThatIsNoStateIsNamed) {
  const tessera::test::TempDir tmp;
  writeText(tmp / "tf.json", "{\"name\": \"grey\", \"color\": []}");
  expectStateError(tmp, tmp / "tf.json",
                   "expected a session state {\"version\", \"settings\": {...}}");
}

TEST(RenderState, AnotherVersionIsNamed) {
  const tessera::test::TempDir tmp;
  nlohmann::json j = jsonOf(saveRender(tmp.path()));
  j["version"] = 7;
  writeText(tmp / "v7.json", j.dump());
  expectStateError(tmp, tmp / "v7.json", "state version 7, this Tessera reads 1");
  j.erase("version");
  writeText(tmp / "none.json", j.dump());
  expectStateError(tmp, tmp / "none.json", "state version null, this Tessera reads 1");
}

TEST(RenderState, ASettingOfTheWrongKindIsNamedWithItsPath) {
  const tessera::test::TempDir tmp;
  const nlohmann::json saved = jsonOf(saveRender(tmp.path()));
  const auto expectEdit = [&](const std::string& pointer, const nlohmann::json& value,
                              const std::string& problem) {
    nlohmann::json j = saved;
    j[nlohmann::json::json_pointer(pointer)] = value;
    writeText(tmp / "edited.json", j.dump());
    SCOPED_TRACE(pointer);
    expectStateError(tmp, tmp / "edited.json", problem);
  };
  expectEdit("/settings/camera/azimuth", "ninety",
             "settings.camera.azimuth is a string, expected a number");
  expectEdit("/settings/jitter", 1, "settings.jitter is a number, expected true or false");
  expectEdit("/settings/background/1", true,
             "settings.background[1] is true or false, expected a number");
  expectEdit("/settings/mode", "xray", "mode 'xray': expected composite, mip, minip or average");
  expectEdit("/settings/step", 99, "step 99: expected voxels in (0, 8]");
}

// A state saved with a fused overlay brings the overlay back: `render
// --state` alone draws the same fused PNG, byte for byte.
TEST(RenderState, TheStatesOverlayIsFusedAgain) {
  const std::string templates = "/usr/share/mricron/templates/";
  if (!fs::exists(templates + "aal.nii.gz")) GTEST_SKIP() << "mricron's templates are missing";
  const tessera::test::TempDir tmp;
  const std::string render = "render " + templates + "ch2.nii.gz --size 64x64 --azimuth 90 ";
  const fs::path state = tmp / "fused.json";
  mustRun(render + "--overlay " + templates + "aal.nii.gz --overlay-labels " + templates +
          "aal.nii.txt --overlay-alpha 0.6 --out " + (tmp / "fused.png").string() +
          " --save-state " + state.string());
  ASSERT_TRUE(jsonOf(state).contains("overlay"));
  EXPECT_EQ(jsonOf(state)["overlay"]["alpha"], 0.6);
  mustRun(render + "--state " + state.string() + " --out " + (tmp / "restored.png").string());
  mustRun(render + "--out " + (tmp / "plain.png").string());

  const std::string fused = bytesOf(tmp / "fused.png");
  ASSERT_GT(fused.size(), 100u);
  EXPECT_TRUE(bytesOf(tmp / "restored.png") == fused);
  EXPECT_TRUE(bytesOf(tmp / "plain.png") != fused);  // the overlay shows
}
