// `tessera view STORE` with several channels (docs/channels.md): the channel
// list's state (the slab hidden, the sphere yellow, the rod's window
// narrowed — what the panel's toggle, colour picker and window set through
// session::ChannelView) started from a state file, and the 3D view's
// screenshot under Xvfb against `tessera render STORE --channels 0,2
// --channel-colors ... --channel-windows ...`. Skipped where xvfb-run or the
// desktop viewer is missing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "support/ChannelStore.h"
#include "support/ShellCommand.h"
#include "support/TestSupport.h"
#include "tessera/core/Image.h"
#include "tessera/session/Session.h"

namespace tessera::viewer {
namespace {

using test::CommandRun;
using test::runCommand;

constexpr int kPanel = 390;  // desktop::kPanelWidth
constexpr int kView = 256;
constexpr int kEdge = 24;  // the patient-direction letters sit at the view's edges

// PSNR over R, G, B of the view's inside (the screenshot's pixels right of
// the panel) against the CLI's image of the view's size.
double viewPsnr(const Image& shot, const Image& cli, int* lit) {
  double sum = 0.0;
  long n = 0;
  *lit = 0;
  for (int y = kEdge; y < kView - kEdge; ++y) {
    for (int x = kEdge; x < kView - kEdge; ++x) {
      const std::uint8_t *p = shot.pixel(kPanel + x, y), *q = cli.pixel(x, y);
      for (int k = 0; k < 3; ++k, ++n) sum += (p[k] - q[k]) * (p[k] - q[k]);
      *lit += q[0] + q[1] + q[2] > 30 ? 1 : 0;
    }
  }
  const double mse = sum / static_cast<double>(n);
  return mse == 0.0 ? 999.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

TEST(DesktopChannels, ChannelListStateShowsWhatTheCommandLineRenders) {
  if (runCommand("command -v xvfb-run").status != 0) GTEST_SKIP() << "xvfb-run not installed";
  if (runCommand(std::string(TESSERA_CLI_PATH) + " view --help").output.find("--screenshot") ==
      std::string::npos) {
    GTEST_SKIP() << "tessera built without GLFW/ImGui";
  }
  test::TempDir dir;
  const std::string store = (dir / "three.ome.zarr").string();
  test::writeChannelStore(store, {.dims = {48, 48, 24}});
  const std::string look = " --tf grey --opacity-scale 20 --azimuth 30 --elevation 20 ";
  {
    // The state the panel leaves: what ChannelView's edits write.
    session::Session s("native");
    s.settings().tf = TransferFunction::preset("grey");
    s.settings().render.opacityScale = 20.0;
    s.settings().camera.azimuthDeg = 30.0;
    s.settings().camera.elevationDeg = 20.0;
    session::ChannelView& view = s.channelView();
    ASSERT_TRUE(view.open(store));
    view.setVisible(1, false);
    view.setColor(0, {1.0, 1.0, 0.0});
    view.setWindow(2, {100.0, 2000.0});
    s.saveState((dir / "state.json").string());
  }
  const CommandRun cli = runCommand(
      std::string(TESSERA_CLI_PATH) + " render " + store + look +
      "--channels 0,2 --channel-colors ffff00,0080ff --channel-windows 100:3000,100:2000 "
      "--profile gles3 --size " +
      std::to_string(kView) + "x" + std::to_string(kView) + " --out " + (dir / "cli.png").string());
  ASSERT_EQ(cli.status, 0) << cli.output;
  const CommandRun view =
      runCommand("xvfb-run -a -s '-screen 0 1024x640x24' " + std::string(TESSERA_CLI_PATH) +
                 " view " + store + " --layout single --frames 3 --size " +
                 std::to_string(kPanel + kView) + "x" + std::to_string(kView) + " --state " +
                 (dir / "state.json").string() + " --screenshot " + (dir / "view.png").string());
  ASSERT_EQ(view.status, 0) << view.output;
  int lit = 0;
  const double db =
      viewPsnr(Image::readPng(dir / "view.png"), Image::readPng(dir / "cli.png"), &lit);
  std::printf(
      "  [measured] desktop channel view vs tessera render --channels 0,2: %.1f dB, %d lit\n", db,
      lit);
  EXPECT_GE(db, 40.0);
  EXPECT_GT(lit, 1000);  // the channels show
}

}  // namespace
}  // namespace tessera::viewer
