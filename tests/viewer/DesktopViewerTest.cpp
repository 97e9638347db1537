// `tessera view` end to end: a screenshot of the window under Xvfb (skipped
// where xvfb-run or the desktop viewer is missing), and the message without
// a display.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "support/ShellCommand.h"
#include "support/TestSupport.h"
#include "tessera/core/Image.h"
#include "tessera/io/Procedural.h"
#include "tessera/render/LabelTable.h"

namespace tessera::viewer {
namespace {

using test::CommandRun;
const auto run = test::runCommand;

bool desktopViewerBuilt() {
  return run(std::string(TESSERA_CLI_PATH) + " view --help").output.find("--screenshot") !=
             std::string::npos &&
         run(std::string("env -u DISPLAY ") + TESSERA_CLI_PATH + " view gen:sphere:8")
                 .output.find("without the desktop viewer") == std::string::npos;
}

// Fraction of pixels in [x0, x1) that are not (near) black.
double litFraction(const Image& img, int x0, int x1) {
  long lit = 0, all = 0;
  for (int y = 0; y < img.height(); ++y) {
    for (int x = x0; x < x1; ++x, ++all) {
      const std::uint8_t* p = img.pixel(x, y);
      lit += p[0] + p[1] + p[2] > 60 ? 1 : 0;
    }
  }
  return static_cast<double>(lit) / static_cast<double>(all);
}

TEST(DesktopViewer, ScreenshotUnderXvfbShowsTheVolumeBesideThePanel) {
  if (run("command -v xvfb-run").status != 0) GTEST_SKIP() << "xvfb-run not installed";
  if (!desktopViewerBuilt()) GTEST_SKIP() << "tessera built without GLFW/ImGui";
  test::TempDir dir;
  const auto png = dir / "view.png";
  const CommandRun r =
      run("xvfb-run -a -s '-screen 0 1024x640x24' " + std::string(TESSERA_CLI_PATH) +
          " view gen:shepp-logan:48 --size 960x600 --azimuth 30 --frames 2 --screenshot " +
          png.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const Image img = Image::readPng(png);
  ASSERT_EQ(img.width(), 960);
  ASSERT_EQ(img.height(), 600);
  // Panel (390 px wide): ImGui's widgets; view: the phantom, black around it.
  const double panel = litFraction(img, 0, 390), view = litFraction(img, 390, 960);
  EXPECT_GT(panel, 0.05) << r.output;
  EXPECT_GT(view, 0.05) << r.output;
  EXPECT_LT(view, 0.9) << r.output;
}

// F1/? shows the shortcuts over the view (--help-overlay opens it), and an
// opened file lands in $XDG_CONFIG_HOME/tessera/recent-files.json.
TEST(DesktopViewer, HelpOverlayListsShortcutsAndOpenedFilesAreRemembered) {
  if (run("command -v xvfb-run").status != 0) GTEST_SKIP() << "xvfb-run not installed";
  if (!desktopViewerBuilt()) GTEST_SKIP() << "tessera built without GLFW/ImGui";
  test::TempDir dir;
  const auto volume = dir / "phantom.nrrd";
  ASSERT_EQ(
      run(std::string(TESSERA_CLI_PATH) + " convert gen:shepp-logan:32 " + volume.string()).status,
      0);
  auto view = [&](const std::string& extra, const std::filesystem::path& png) {
    return run("XDG_CONFIG_HOME=" + (dir / "config").string() +
               " xvfb-run -a -s '-screen 0 1024x640x24' " + TESSERA_CLI_PATH + " view " +
               volume.string() + " --size 960x600 --frames 2 --screenshot " + png.string() + " " +
               extra);
  };
  const CommandRun plain = view("", dir / "plain.png");
  ASSERT_EQ(plain.status, 0) << plain.output;
  const CommandRun help = view("--help-overlay", dir / "help.png");
  ASSERT_EQ(help.status, 0) << help.output;
  // The overlay: a table over the middle of the view changes a good part of it.
  const Image a = Image::readPng(dir / "plain.png"), b = Image::readPng(dir / "help.png");
  int changed = 0, all = 0;
  for (int y = 200; y < 400; ++y) {
    for (int x = 500; x < 850; ++x, ++all) {
      for (int c = 0; c < 3; ++c) {
        if (std::abs(a.pixel(x, y)[c] - b.pixel(x, y)[c]) > 24) {
          ++changed;
          break;
        }
      }
    }
  }
  EXPECT_GT(changed, all / 5) << help.output;

  std::ifstream in(dir / "config" / "tessera" / "recent-files.json");
  ASSERT_TRUE(in) << "no recent-files list";
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find(std::filesystem::absolute(volume).lexically_normal().string()),
            std::string::npos)
      << text.str();
}

// The four-up layout: slice views in three quadrants with the picked
// region's red box; the grid view starts; a crosshair outside the volume
// is refused with the volume's range.
TEST(DesktopViewer, FourUpShowsSlicesWithThePickedRegion) {
  if (run("command -v xvfb-run").status != 0) GTEST_SKIP() << "xvfb-run not installed";
  if (!desktopViewerBuilt()) GTEST_SKIP() << "tessera built without GLFW/ImGui";
  test::TempDir dir;
  const std::string base = "xvfb-run -a -s '-screen 0 1024x640x24' " +
                           std::string(TESSERA_CLI_PATH) +
                           " view gen:shepp-logan:48 --size 960x600 --frames 2 ";
  const auto png = dir / "four.png";
  const CommandRun r =
      run(base + "--crosshair 12 24 24 --pick --region-side 16 --screenshot " + png.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const Image img = Image::readPng(png);
  // Right of the 390-px panel: axial top-left, 3D top-right, sagittal
  // bottom-left, coronal bottom-right.
  auto count = [&](int x0, int x1, int y0, int y1, auto&& pred) {
    int n = 0;
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) n += pred(img.pixel(x, y)) ? 1 : 0;
    }
    return n;
  };
  auto red = [](const std::uint8_t* p) { return p[0] > 180 && p[1] < 120 && p[2] < 110; };
  auto grey = [](const std::uint8_t* p) {
    return p[0] > 40 && std::abs(p[0] - p[1]) < 6 && std::abs(p[1] - p[2]) < 6;
  };
  for (const auto& [x0, y0] : {std::pair{390, 0}, std::pair{390, 300}, std::pair{675, 300}}) {
    EXPECT_GT(count(x0, x0 + 285, y0, y0 + 300, red), 40) << x0 << "," << y0;
    EXPECT_GT(count(x0, x0 + 285, y0, y0 + 300, grey), 2000) << x0 << "," << y0;
  }
  const CommandRun grid = run(base + "--mode grid --screenshot " + (dir / "grid.png").string());
  EXPECT_EQ(grid.status, 0) << grid.output;
  const CommandRun bad = run(base + "--crosshair 48 0 0 --screenshot " + (dir / "x.png").string());
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.output.find("outside the volume"), std::string::npos) << bad.output;
}

// The window's session state round-trips: a view saved with --save-state
// (camera, TF, render mode, crosshair, the region shown) and started again
// from it with --state shows the same 3D view, pixel for pixel, while the
// same volume without it does not; a bad state file ends the command naming it.
TEST(DesktopViewer, SavedStateRestoresTheSameView) {
  if (run("command -v xvfb-run").status != 0) GTEST_SKIP() << "xvfb-run not installed";
  if (!desktopViewerBuilt()) GTEST_SKIP() << "tessera built without GLFW/ImGui";
  test::TempDir dir;
  const std::string base = "xvfb-run -a -s '-screen 0 1024x640x24' " +
                           std::string(TESSERA_CLI_PATH) +
                           " view gen:shepp-logan:48 --size 960x600 --layout single --frames 3 ";
  const auto state = dir / "state" / "view.json";
  const CommandRun saved =
      run(base +
          "--azimuth 30 --elevation 10 --tf ct-bone --render-mode mip --crosshair 12 24 24 "
          "--pick --region-side 16 --mode region --screenshot " +
          (dir / "a.png").string() + " --save-state " + state.string());
  ASSERT_EQ(saved.status, 0) << saved.output;
  ASSERT_TRUE(std::filesystem::exists(state));
  const CommandRun restored =
      run(base + "--state " + state.string() + " --screenshot " + (dir / "b.png").string());
  ASSERT_EQ(restored.status, 0) << restored.output;
  const CommandRun plain = run(base + "--screenshot " + (dir / "c.png").string());
  ASSERT_EQ(plain.status, 0) << plain.output;
  const Image a = Image::readPng(dir / "a.png"), b = Image::readPng(dir / "b.png"),
              c = Image::readPng(dir / "c.png");
  // The 3D view right of the 390-px panel (the panel's status line has times).
  auto differing = [](const Image& x, const Image& y) {
    int n = 0;
    for (int row = 0; row < x.height(); ++row) {
      for (int col = 400; col < x.width(); ++col) {
        const std::uint8_t *p = x.pixel(col, row), *q = y.pixel(col, row);
        n += std::abs(p[0] - q[0]) + std::abs(p[1] - q[1]) + std::abs(p[2] - q[2]) > 6 ? 1 : 0;
      }
    }
    return n;
  };
  EXPECT_EQ(differing(a, b), 0);
  EXPECT_GT(differing(a, c), 5000);  // the state is what made the view differ
  EXPECT_GT(litFraction(a, 400, a.width()), 0.02);

  std::ofstream(dir / "bad.json")
      << "{\"version\": 1, \"settings\": {\"version\": 1, \"mode\": \"loud\"}}";
  const CommandRun bad = run(base + "--state " + (dir / "bad.json").string() + " --screenshot " +
                             (dir / "x.png").string());
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.output.find((dir / "bad.json").string() + ": "), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("loud"), std::string::npos) << bad.output;
}

// --labels: the 3D view shows the volume's labels in the table's colours
// (the Shepp-Logan phantom's few integer values: the default palette's
// colours, which the ordinary TF does not show), a label file sets names and colours, and a
// bad label file is refused naming the file and line.
TEST(DesktopViewer, LabelsShowTheTablesColours) {
  if (run("command -v xvfb-run").status != 0) GTEST_SKIP() << "xvfb-run not installed";
  if (!desktopViewerBuilt()) GTEST_SKIP() << "tessera built without GLFW/ImGui";
  test::TempDir dir;
  const std::string base = "xvfb-run -a -s '-screen 0 1024x640x24' " +
                           std::string(TESSERA_CLI_PATH) +
                           " view gen:shepp-logan:48 --size 960x600 --layout single --frames 2 ";
  // Pixels of the view (right of the panel) in one of the default palette's colours.
  std::vector<glm::ivec3> palette;
  for (const auto& [value, label] :
       render::LabelTable::defaultFor(makeSheppLogan({48, 48, 48})).labels) {
    palette.push_back(glm::ivec3(glm::round(label.color * 255.0)));
  }
  auto inPalette = [&](const Image& img) {
    int n = 0;
    for (int y = 0; y < img.height(); ++y) {
      for (int x = 400; x < img.width(); ++x) {
        const std::uint8_t* p = img.pixel(x, y);
        for (const glm::ivec3& c : palette) {
          if (std::abs(p[0] - c.r) <= 1 && std::abs(p[1] - c.g) <= 1 && std::abs(p[2] - c.b) <= 1) {
            ++n;
            break;
          }
        }
      }
    }
    return n;
  };
  const CommandRun plain = run(base + "--screenshot " + (dir / "plain.png").string());
  ASSERT_EQ(plain.status, 0) << plain.output;
  const CommandRun labels = run(base + "--labels --screenshot " + (dir / "labels.png").string());
  ASSERT_EQ(labels.status, 0) << labels.output;
  const int before = inPalette(Image::readPng(dir / "plain.png"));
  const int after = inPalette(Image::readPng(dir / "labels.png"));
  std::printf("  [measured] view pixels in the palette: %d plain, %d as labels\n", before, after);
  EXPECT_GT(after, 5000);
  EXPECT_GT(after, 5 * before + 1000);

  {
    std::ofstream table(dir / "table.txt");
    table << "# value name\n1 outer\nnot-a-number here\n";
  }
  const CommandRun bad = run(base + "--labels " + (dir / "table.txt").string() + " --screenshot " +
                             (dir / "bad.png").string());
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.output.find("table.txt:3"), std::string::npos) << bad.output;
}

TEST(DesktopViewer, WithoutADisplayItSaysWhatToDo) {
  if (!desktopViewerBuilt()) GTEST_SKIP() << "tessera built without GLFW/ImGui";
  const CommandRun r = run("env -u DISPLAY -u WAYLAND_DISPLAY " + std::string(TESSERA_CLI_PATH) +
                           " view gen:sphere:16");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("xvfb-run"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace tessera::viewer
