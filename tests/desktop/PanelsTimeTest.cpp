// The desktop viewer's time panel (frontends/desktop/PanelsTime.cpp), drawn
// in an ImGui context without a window (HeadlessImGui.h) with the frame's
// playback step before it, as DesktopApp's frame runs them, on a clock the
// test moves: the slider typed to a time point shows that time point, whose
// frame is `tessera render SERIES --time T`'s; the rate typed in and "Play"
// show every time point in order, one per period of that rate, each frame
// the command line's for it; "Pause" holds the time point shown; a time
// point that cannot be read stops playback with its message on the error
// line, the window going on.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "desktop/HeadlessImGui.h"
#include "desktop/PanelFrames.h"
#include "desktop/Panels.h"
#include "desktop/RecordingHost.h"
#include "support/TestSupport.h"
#include "tessera/io/NiftiWriter.h"
#include "tessera/session/Session.h"

namespace tessera::desktop {
namespace {

using test::HeadlessImGui;
namespace fs = std::filesystem;
constexpr int kSize = test::kPanelFrameSize;
constexpr int kTimes = 6;

// Time point t of the series: 32^3 u8, a dim sphere shell and a bright 8^3
// cube whose x moves 3 voxels per time point. Every time point holds 0 and
// 255, so that its own window (what `render --time T` reads alone) is the
// first one's, which the series keeps.
Volume timePoint(int t) {
  Volume v = Volume::allocate({32, 32, 32}, ScalarType::U8, "series");
  for (int z = 0; z < 32; ++z) {
    for (int y = 0; y < 32; ++y) {
      for (int x = 0; x < 32; ++x) {
        const double r = glm::length(glm::dvec3(x, y, z) - glm::dvec3(15.5)) - 12.0;
        double value = 60.0 * std::exp(-r * r / 4.0);
        const int x0 = 4 + 3 * t;
        if (x >= x0 && x < x0 + 8 && y >= 12 && y < 20 && z >= 12 && z < 20) value = 255.0;
        v.setValueAtIndex(v.index(x, y, z), std::round(value));
      }
    }
  }
  v.invalidateRange();
  return v;
}

// A 4-D NIfTI of kTimes time points: writeNifti's 3-D file with the time
// points after the first appended and dim[0], dim[4] set.
std::string writeSeries(const std::filesystem::path& path) {
  const Volume first = timePoint(0);
  writeNifti(first, path);
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  const std::int16_t dims[2] = {4, kTimes};
  f.seekp(40);  // dim[0]
  f.write(reinterpret_cast<const char*>(&dims[0]), 2);
  f.seekp(48);  // dim[4]
  f.write(reinterpret_cast<const char*>(&dims[1]), 2);
  f.seekp(0, std::ios::end);
  for (int t = 1; t < kTimes; ++t) {
    const Volume v = timePoint(t);
    f.write(reinterpret_cast<const char*>(v.bytes().data()),
            static_cast<std::streamsize>(v.byteSize()));
  }
  return path.string();
}

// The look: --tf grey, and the camera the user turned the view to
// (--azimuth 30 --elevation 20).
void look(session::Settings& s) {
  s.tf = TransferFunction::preset("grey");
  s.tfIsDefault = false;
  s.camera.azimuthDeg = 30.0;
  s.camera.elevationDeg = 20.0;
}
void turn(viewer::Viewer& v) {
  v.camera().azimuthDeg = 30.0;
  v.camera().elevationDeg = 20.0;
}

class PanelsTime : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDir>();
    writeSeries(dir_->path() / "series.nii");
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static std::string series() { return (dir_->path() / "series.nii").string(); }

  // `tessera render SERIES --time T --tf grey --azimuth 30 --elevation 20`
  // (a fresh session; one frame per time point, kept).
  const Image& cliFrame(int t) {
    auto it = cli_.find(t);
    if (it != cli_.end()) return it->second;
    session::Session cli("native");
    look(cli.settings());
    session::OpenOptions open;
    open.time = t;
    cli.open(series(), open);
    return cli_.emplace(t, cli.render(kSize, kSize)).first->second;
  }
  // The frame of the time point shown: the session's look (what the desktop
  // shows and Save state writes) rendered as `tessera render` renders.
  Image shownFrame() {
    s.setSettings(s.currentSettings());
    return s.render(kSize, kSize);
  }
  void SetUp() override {
    look(s.settings());
    host.openFile(series());
    ASSERT_EQ(host.error, "");
    ASSERT_NE(s.series(), nullptr);
    ASSERT_EQ(s.series()->count(), kTimes);
    turn(s.view());
    ui.frame();
  }
  // Frames (one every 5 ms of the clock) until time point `t` is shown; a
  // generous stall guard of 20 s.
  bool frameUntilShown(int t) {
    const auto start = std::chrono::steady_clock::now();
    while (s.timePoint() != t) {
      if (std::chrono::steady_clock::now() - start > std::chrono::seconds(20)) return false;
      clock += 5.0;
      ui.frame();
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return true;
  }
  void typeInto(const char* label, const char* text) { ui.typeInto(kPanelTitle, label, text); }

  session::Session s{"native"};
  test::RecordingHost host{s};
  TimeUi timeUi;
  double clock = 1000.0;        // the frame's time (ms), as steadyNowMs gives it
  std::vector<int> shown;       // the time points stepTime showed, in order
  std::vector<double> shownAt;  // the clock when each was
  // The frame as DesktopApp's runFrame draws it: the playback's step, then
  // the control panel with the time panel.
  HeadlessImGui ui{[this] {
    if (stepTime(s, timeUi, host, clock)) {
      shown.push_back(s.timePoint());
      shownAt.push_back(clock);
    }
    beginControlPanel(HeadlessImGui::kHeight);
    panelTime(s, timeUi, host, clock);
    ImGui::End();
  }};
  std::map<int, Image> cli_;
  static std::unique_ptr<test::TempDir> dir_;
};
std::unique_ptr<test::TempDir> PanelsTime::dir_;

TEST_F(PanelsTime, TheSliderShowsTheTimePointAsRenderTimeRendersIt) {
  EXPECT_EQ(s.timePoint(), 0);
  EXPECT_EQ(test::differingPixels(shownFrame(), cliFrame(0)), 0);
  for (const int t : {3, 5, 1}) {
    SCOPED_TRACE("time point " + std::to_string(t));
    typeInto("time point", std::to_string(t).c_str());
    ASSERT_TRUE(frameUntilShown(t)) << "time point " << t << " never shown";
    EXPECT_FALSE(s.playback().playing());
    EXPECT_EQ(host.error, "");
    const Image frame = shownFrame();
    const int off = test::differingPixels(frame, cliFrame(t));
    const int fromFirst = test::differingPixels(frame, cliFrame(0), 2);
    std::printf("slider to %d: %d pixels differ from render --time %d's frame, %d from t 0's\n", t,
                off, t, fromFirst);
    EXPECT_EQ(off, 0);
    EXPECT_GT(fromFirst, 0);  // the cube moved: another time point, not the first one again
  }
  EXPECT_GE(host.viewChanges, 3);  // the window's slice views follow
}

TEST_F(PanelsTime, PlayAtTheRateTypedInShowsEveryTimePointInOrderPauseHolds) {
  typeInto("per second", "25");
  EXPECT_EQ(s.playback().fps(), 25.0);
  ui.click(kPanelTitle, {"Play"});
  ASSERT_TRUE(s.playback().playing());
  const double started = clock;
  const auto start = std::chrono::steady_clock::now();
  std::size_t checked = 0;
  int framesOff = 0;
  // Two rounds and one: every time point twice, wrapping after the last.
  while (shown.size() < 2 * kTimes + 1 &&
         std::chrono::steady_clock::now() - start < std::chrono::seconds(20)) {
    clock += 5.0;
    ui.frame();
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    for (; checked < shown.size(); ++checked)
      framesOff += test::differingPixels(shownFrame(), cliFrame(shown[checked]));
  }
  ASSERT_EQ(shown.size(), 2u * kTimes + 1) << "playback stalled";
  std::vector<double> periods;
  for (std::size_t i = 0; i < shown.size(); ++i) {
    EXPECT_EQ(shown[i], static_cast<int>(i + 1) % kTimes) << "skipped or repeated at " << i;
    periods.push_back(shownAt[i] - (i ? shownAt[i - 1] : started));
  }
  std::vector<double> sorted = periods;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  std::printf(
      "play at 25/s: %zu time points shown in order over %.0f ms of the clock; period min %.0f, "
      "median %.0f, max %.0f ms (40 expected); %llu late frames; %d pixels differ from render "
      "--time T's frames in all\n",
      shown.size(), shownAt.back() - started, sorted.front(), median, sorted.back(),
      static_cast<unsigned long long>(s.playback().lateFrames()), framesOff);
  EXPECT_GE(sorted.front(), 40.0);  // never early: 25 per second at most
  EXPECT_EQ(median, 40.0);
  EXPECT_EQ(framesOff, 0);

  ui.click(kPanelTitle, {"Pause"});
  EXPECT_FALSE(s.playback().playing());
  const int held = s.timePoint();
  const std::size_t shownBefore = shown.size();
  for (int i = 0; i < 40; ++i) {  // 200 ms of the clock: five periods
    clock += 5.0;
    ui.frame();
  }
  EXPECT_EQ(s.timePoint(), held);
  EXPECT_EQ(shown.size(), shownBefore);
}

// A series whose file lost its last time points after it was opened, read
// ahead two time points at a time (a host budget of 256 KiB: a quarter holds
// two of 32 KiB): playback shows 0 and 1, then stops at 2 with the reader's
// message, and the frames after it go on (no exception leaves the frame).
TEST_F(PanelsTime, ATimePointThatCannotBeReadStopsPlaybackOnTheErrorLine) {
  const test::BudgetOverride budget(256 << 10);
  const fs::path cut = dir_->path() / "cut.nii";
  fs::copy_file(series(), cut, fs::copy_options::overwrite_existing);
  host.openFile(cut.string());
  ASSERT_EQ(host.error, "");
  ASSERT_NE(s.series(), nullptr);
  EXPECT_EQ(s.series()->keep(), 2);
  // Time point 1 read ahead (on the series' thread) before the file is cut.
  const auto readAhead = std::chrono::steady_clock::now();
  while (!s.series()->isRead(1) &&
         std::chrono::steady_clock::now() - readAhead < std::chrono::seconds(20)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_TRUE(s.series()->isRead(1));
  fs::resize_file(cut, fs::file_size(cut) - 4 * timePoint(0).byteSize());  // 2..5 gone
  ui.click(kPanelTitle, {"Play"});
  const auto start = std::chrono::steady_clock::now();
  while (host.error.empty() &&
         std::chrono::steady_clock::now() - start < std::chrono::seconds(20)) {
    clock += 5.0;
    ui.frame();
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::printf("error line: %s\n", host.error.c_str());
  EXPECT_EQ(
      host.error.rfind(cut.string() + ": playback stopped: time point 2 could not be read: ", 0),
      0u)
      << host.error;
  EXPECT_FALSE(s.playback().playing());
  EXPECT_EQ(s.timePoint(), 1);
  EXPECT_EQ(shown, std::vector<int>({1}));
  for (int i = 0; i < 10; ++i) {
    clock += 5.0;
    ui.frame();
  }
  EXPECT_EQ(s.timePoint(), 1);
}

}  // namespace
}  // namespace tessera::desktop
