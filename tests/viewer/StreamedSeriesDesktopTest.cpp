// `tessera view STORE --bricks --play FPS` under Xvfb: a store's t axis
// played over bricks in the desktop viewer (session::StreamedFrames). With
// --play-record the viewer writes the 3D view's frame of every time point
// shown once it is complete (what playback moves on from); each must equal
// that time point rendered in core (and be nearer it than any other time
// point: no stale frame), every time point shown once per loop, in order,
// and the textures within the profile's budget. Skipped where xvfb-run or
// the desktop viewer is missing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include "support/ShellCommand.h"
#include "support/TestSupport.h"
#include "support/TimeStore.h"
#include "tessera/core/Image.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/session/Session.h"

namespace tessera::viewer {
namespace {

using test::CommandRun;
using test::runCommand;

constexpr int kPanel = 390;  // desktop::kPanelWidth
constexpr int kView = 96;
constexpr int kTimes = 5;

// `tessera view STORE --bricks --play 30` of 6 time points after the first,
// recording each complete frame into `shots` (exit status checked by the
// caller).
CommandRun playOverBricks(const std::string& store, const std::string& shots,
                          const std::filesystem::path& dir) {
  return runCommand("timeout 300 xvfb-run -a -s '-screen 0 1024x640x24' " +
                    std::string(TESSERA_CLI_PATH) + " view " + store +
                    " --bricks --layout single --tf grey --azimuth 30 --elevation 20 --size " +
                    std::to_string(kPanel + kView) + "x" + std::to_string(kView) +
                    " --play 30 --play-time-points 6 --play-record " + shots + " --screenshot " +
                    (dir / "view.png").string());
}

// The time points the viewer printed as shown ("shown N: time point T
// complete"), each N in turn; every loop must show 0..kTimes-1 in order.
// Each recorded frame against `expected` of its time point (>= 40 dB) and
// nearer it than any other time point's by 5 dB (no stale bricks).
void expectEveryTimePointShownAsExpected(const std::string& output, const std::string& shots,
                                         const std::vector<Image>& expected, const char* what) {
  const std::regex line(R"(shown (\d+): time point (\d+) complete)");
  std::vector<int> sequence;
  for (auto it = std::sregex_iterator(output.begin(), output.end(), line);
       it != std::sregex_iterator(); ++it) {
    EXPECT_EQ(std::stoi((*it)[1].str()), static_cast<int>(sequence.size()));
    sequence.push_back(std::stoi((*it)[2].str()));
  }
  ASSERT_EQ(sequence.size(), 7u) << output;
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    const int t = sequence[i];
    EXPECT_EQ(t, static_cast<int>(i % kTimes)) << "at " << i << ": skipped or out of order";
    char name[64];
    std::snprintf(name, sizeof name, "%04zu-t%d.png", i, t);
    const Image shown = Image::readPng(std::filesystem::path(shots) / name);
    const double own = psnr(shown, expected[static_cast<std::size_t>(t)]);
    double other = 0.0;
    for (int u = 0; u < kTimes; ++u) {
      if (u != t) other = std::max(other, psnr(shown, expected[static_cast<std::size_t>(u)]));
    }
    std::printf(
        "  [measured] %s, shown %zu: time point %d, %.1f dB against it, %.1f dB against the "
        "nearest other\n",
        what, i, t, own, other);
    EXPECT_GE(own, 40.0) << "time point " << t;
    EXPECT_GT(own, other + 5.0) << "time point " << t << " shows another's bricks";
  }
}

TEST(DesktopStreamedSeries, PlaysEveryTimePointOverBricksInOrderEachAsInCore) {
  if (runCommand("command -v xvfb-run").status != 0) GTEST_SKIP() << "xvfb-run not installed";
  if (runCommand(std::string(TESSERA_CLI_PATH) + " view --help").output.find("--screenshot") ==
      std::string::npos) {
    GTEST_SKIP() << "tessera built without GLFW/ImGui";
  }
  test::TempDir dir;
  const std::string store = test::writeTimeStore(dir.path(), kTimes, 1).string();
  // Each time point in core, as `tessera render STORE --time T` draws it.
  std::vector<Image> inCore;
  {
    session::Session s("gles3");
    s.settings().tf = TransferFunction::preset("grey");
    s.settings().camera.azimuthDeg = 30.0;
    s.settings().camera.elevationDeg = 20.0;
    for (int t = 0; t < kTimes; ++t) {
      session::OpenOptions o;
      o.time = t;
      s.open(store, o);
      ASSERT_FALSE(s.streamed());
      inCore.push_back(s.render(kView, kView));
    }
  }
  const std::string shots = (dir / "shown").string();
  const CommandRun view = playOverBricks(store, shots, dir.path());
  ASSERT_EQ(view.status, 0) << view.output;
  std::printf("%s", view.output.c_str());
  expectEveryTimePointShownAsExpected(view.output, shots, inCore,
                                      "desktop over bricks, against in core");
  // The profile's texture budget held (gles3: 512 MiB), and the playback's
  // figures printed.
  const std::regex budgets(R"(budgets: textures peak ([0-9.]+ [KMG]?i?B) of 512 MiB)");
  EXPECT_TRUE(std::regex_search(view.output, budgets)) << view.output;
  EXPECT_NE(view.output.find("time points late"), std::string::npos) << view.output;
}

// A store with three channels and a t axis: `view STORE --bricks --play`
// opens its channel list over the series and plays every channel together
// over bricks, into one layout; each time point's frame against the CPU
// reference of that time point's channels (Session::renderChannels, as
// `render STORE --time T --layout bricks` with the channels draws them).
TEST(DesktopStreamedSeries, PlaysThreeChannelsOverBricksEachAsItsReference) {
  if (runCommand("command -v xvfb-run").status != 0) GTEST_SKIP() << "xvfb-run not installed";
  if (runCommand(std::string(TESSERA_CLI_PATH) + " view --help").output.find("--screenshot") ==
      std::string::npos) {
    GTEST_SKIP() << "tessera built without GLFW/ImGui";
  }
  test::TempDir dir;
  const std::string store = test::writeTimeStore(dir.path(), kTimes, 3).string();
  std::vector<Image> references;
  {
    session::Session s("gles3");
    s.settings().tf = TransferFunction::preset("grey");
    s.settings().camera.azimuthDeg = 30.0;
    s.settings().camera.elevationDeg = 20.0;
    s.settings().layout = "bricks";
    for (int t = 0; t < kTimes; ++t) {
      references.push_back(*s.renderChannels(store, kView, kView, true, t).reference);
    }
  }
  const std::string shots = (dir / "shown").string();
  const CommandRun view = playOverBricks(store, shots, dir.path());
  ASSERT_EQ(view.status, 0) << view.output;
  std::printf("%s", view.output.c_str());
  expectEveryTimePointShownAsExpected(view.output, shots, references,
                                      "desktop, 3 channels over bricks, against the reference");
  EXPECT_NE(view.output.find("over bricks: 1 layouts made"), std::string::npos) << view.output;
}

// --bricks names what it plays: a volume that is not a store with a t axis
// is refused in one line.
TEST(DesktopStreamedSeries, BricksWithoutATimeSeriesIsRefused) {
  if (runCommand("command -v xvfb-run").status != 0) GTEST_SKIP() << "xvfb-run not installed";
  if (runCommand(std::string(TESSERA_CLI_PATH) + " view --help").output.find("--screenshot") ==
      std::string::npos) {
    GTEST_SKIP() << "tessera built without GLFW/ImGui";
  }
  const test::TempDir dir;
  const CommandRun view = runCommand(
      "timeout 120 xvfb-run -a -s '-screen 0 1024x640x24' " + std::string(TESSERA_CLI_PATH) +
      " view gen:sphere:32 --bricks --layout single --size 480x96 --screenshot " +
      (dir / "view.png").string());
  EXPECT_NE(view.status, 0);
  EXPECT_NE(view.output.find("--bricks: "), std::string::npos) << view.output;
  EXPECT_NE(view.output.find("is not an OME-Zarr store with a t axis"), std::string::npos)
      << view.output;
}

}  // namespace
}  // namespace tessera::viewer
