// Time series: the time points after the one shown are read ahead within
// the number kept, a time point let go is read again on a later visit, a
// reader's error reaches the one who waits for it, and playback shows every
// time point in order at its rate, a late one late and none skipped; a
// session shows each time point of a 4-D NIfTI exactly as reading that time
// point alone does, in the first one's window.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "support/ExpectError.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/ByteSource.h"
#include "tessera/io/NiftiWriter.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/session/Session.h"
#include "tessera/session/TimeSeries.h"

namespace tessera::session {
namespace {

// The InputError `action` throws contains every part.
template <class Action>
void expectInputError(Action action, std::initializer_list<const char*> parts) {
  const std::string message = test::inputErrorMessage(action);
  for (const char* part : parts) EXPECT_NE(message.find(part), std::string::npos) << message;
}

// A 2x2x2 volume whose every voxel is t.
Volume constant(int t) {
  Volume v = Volume::allocate(glm::ivec3(2), ScalarType::U8);
  for (std::size_t i = 0; i < v.voxelCount(); ++i) v.setValueAtIndex(i, t);
  return v;
}

TEST(TimeSeries, ReadsAheadOfTheTimePointAskedForWithinWhatItKeeps) {
  TimeSeries series(
      10, [](int t) { return constant(t); }, 3);
  EXPECT_EQ(series.wait(0)->valueAt(0, 0, 0), 0.0);
  EXPECT_EQ(series.wait(2)->valueAt(1, 1, 1), 2.0);  // asks for 2, 3, 4 from here
  EXPECT_EQ(series.wait(4)->valueAt(0, 1, 0), 4.0);
  // 0 first; each time point read once while it stays in the window
  // (0..2, then 2..4, then 4..6: 3 may be skipped when the window moved on
  // before the reader took it); nothing past 6.
  std::vector<int> log = series.readLog();
  ASSERT_FALSE(log.empty());
  EXPECT_EQ(log.front(), 0);
  for (const int t : log) EXPECT_LE(t, 6) << "read beyond the windows asked for";
  for (const int t : {0, 2, 4}) EXPECT_EQ(std::count(log.begin(), log.end(), t), 1) << t;
  // The window 4..6 is read ahead: 5 and 6 arrive without being asked
  // for again (polled, not waited for: a wait would move the window).
  for (int i = 0; i < 2000 && std::count(log.begin(), log.end(), 6) == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    log = series.readLog();
  }
  EXPECT_EQ(std::count(log.begin(), log.end(), 5), 1);
  EXPECT_EQ(std::count(log.begin(), log.end(), 6), 1);
  EXPECT_LE(log.size(), 7u);
  // Past the last it wraps, as looped playback does: 9, 0, 1.
  EXPECT_EQ(series.wait(9)->valueAt(0, 0, 0), 9.0);
  EXPECT_EQ(series.wait(0)->valueAt(0, 0, 0), 0.0);
  EXPECT_GE(series.readLog().back(), 0);
  expectInputError([&] { series.want(10); }, {"time point 10", "0..9"});
  expectInputError(
      [&] {
        TimeSeries(
            4, [](int t) { return constant(t); }, 5);
      },
      {"keeping 5 of 4"});
}

// Without a thread (the WebAssembly page): nothing is read until pump() or
// wait(), each pump() reads the next wanted time point, in the window's
// order, and wait() reads the one it waits for at once.
TEST(TimeSeries, OnPumpReadsOneTimePointPerPumpInTheWindowsOrder) {
  TimeSeries series(
      8, [](int t) { return constant(t); }, 3, TimeSeries::Reading::OnPump);
  EXPECT_EQ(series.reading(), TimeSeries::Reading::OnPump);
  EXPECT_EQ(series.want(2), nullptr);
  EXPECT_TRUE(series.readLog().empty());
  EXPECT_TRUE(series.pump());
  EXPECT_EQ(series.readLog(), std::vector<int>({2}));
  ASSERT_NE(series.want(2), nullptr);
  EXPECT_EQ(series.want(2)->valueAt(0, 0, 0), 2.0);
  EXPECT_TRUE(series.pump());
  EXPECT_TRUE(series.pump());
  EXPECT_FALSE(series.pump()) << "the window 2..4 is read";
  EXPECT_EQ(series.readLog(), std::vector<int>({2, 3, 4}));
  EXPECT_EQ(series.wait(7)->valueAt(1, 1, 1), 7.0);  // read now, no thread to wait for
  EXPECT_EQ(series.readLog().back(), 7);
  TimeSeries background(
      3, [](int t) { return constant(t); }, 2);
  EXPECT_FALSE(background.pump()) << "a series with its own thread reads there";
  EXPECT_EQ(background.wait(1)->valueAt(0, 0, 0), 1.0);
}

// A page reading fetched bytes (an OME-Zarr store in the browser): a time
// point is read only once its bytes have arrived, the most urgent ones
// asked for first and no more than `ahead` at once; one that arrives late
// is read then, in the window's order.
TEST(TimeSeries, OnPumpReadsOnlyWhatHasArrivedAskingForAtMostAheadAtOnce) {
  TimeSeries series(
      10, [](int t) { return constant(t); }, 5, TimeSeries::Reading::OnPump);
  std::vector<bool> here(10, false);
  std::vector<int> asked;
  series.setArrival(
      [&](int t) {
        if (!here[std::size_t(t)]) asked.push_back(t);
        return here[std::size_t(t)];
      },
      2);
  EXPECT_EQ(series.want(3), nullptr);
  EXPECT_FALSE(series.pump()) << "nothing has arrived";
  EXPECT_EQ(asked, std::vector<int>({3, 4})) << "the two most urgent, no more";
  EXPECT_TRUE(series.readLog().empty());
  here[4] = true;  // arrived out of order: read, 3 still asked for
  asked.clear();
  EXPECT_TRUE(series.pump());
  EXPECT_EQ(series.readLog(), std::vector<int>({4}));
  EXPECT_EQ(asked, std::vector<int>({3}));
  EXPECT_EQ(series.want(3), nullptr);
  asked.clear();
  EXPECT_FALSE(series.pump());
  EXPECT_EQ(asked, std::vector<int>({3, 5})) << "4 is held: the next two not at hand";
  here[3] = here[5] = here[6] = here[7] = true;
  while (series.pump()) {
  }
  EXPECT_EQ(series.readLog(), std::vector<int>({4, 3, 5, 6, 7}));
  ASSERT_NE(series.want(3), nullptr);
  EXPECT_EQ(series.want(3)->valueAt(0, 0, 0), 3.0);
  expectInputError([&] { series.setArrival([](int) { return true; }, 6); }, {"6", "1..5"});
  TimeSeries background(
      3, [](int t) { return constant(t); }, 2);
  expectInputError([&] { background.setArrival([](int) { return true; }, 1); }, {"pump"});
}

TEST(TimeSeries, KeepsWhatTheBudgetHoldsAndAtLeastTheNext) {
  EXPECT_EQ(TimeSeries::keepWithin(100, 10, 20), 10);
  EXPECT_EQ(TimeSeries::keepWithin(1000, 10, 20), 20);
  EXPECT_EQ(TimeSeries::keepWithin(5, 10, 20), 2);
  EXPECT_EQ(TimeSeries::keepWithin(5, 10, 1), 1);
}

TEST(TimeSeries, AReadersErrorReachesWhoWaitsForThatTimePoint) {
  TimeSeries series(
      5,
      [](int t) {
        if (t == 3) throw InputError("series.nii: time point 3 is corrupt");
        return constant(t);
      },
      5);
  EXPECT_EQ(series.wait(2)->valueAt(0, 0, 0), 2.0);
  expectInputError([&] { series.wait(3); }, {"series.nii: time point 3 is corrupt"});
  expectInputError([&] { series.rethrowFailure(3); }, {"time point 3 is corrupt"});
  EXPECT_NO_THROW(series.rethrowFailure(2));
  EXPECT_EQ(series.wait(4)->valueAt(0, 0, 0), 4.0);
}

TEST(Playback, ShowsEveryTimePointInOrderALateOneLate) {
  // 10 time points per second, frames every 16 ms for 3 s; time point 4 is
  // read 400 ms late, every other one on time.
  Playback play(10.0);
  play.play(0.0);
  int shown = 0;
  std::vector<int> sequence{0};
  std::vector<double> shownAt{0.0};
  for (double now = 0.0; now < 3000.0; now += 16.0) {
    const int next = (shown + 1) % 10;
    const bool ready = next != 4 || now >= 800.0;
    const int s = play.step(now, shown, 10, ready);
    if (s != shown) {
      sequence.push_back(s);
      shownAt.push_back(now);
      shown = s;
    }
  }
  for (std::size_t i = 1; i < sequence.size(); ++i) {
    EXPECT_EQ(sequence[i], (sequence[i - 1] + 1) % 10) << "skipped at " << i;
  }
  EXPECT_GT(play.lateFrames(), 0u);
  EXPECT_EQ(play.advances(), sequence.size() - 1);
  // Only 4 was shown more than a period after it was due (800 ms for 400).
  EXPECT_EQ(play.lateTimePoints(), 1u);
  // 4 shown when it arrived, and the rest a period apart after it.
  const auto four = std::find(sequence.begin(), sequence.end(), 4) - sequence.begin();
  EXPECT_NEAR(shownAt[four], 800.0, 16.0);
  EXPECT_NEAR(shownAt[four + 1] - shownAt[four], 100.0, 16.0);
  // On time elsewhere: 1, 2, 3 at 100, 200, 300 ms (within a frame).
  for (int i = 1; i <= 3; ++i) EXPECT_NEAR(shownAt[i], 100.0 * i, 16.0);
  expectInputError([&] { play.setFps(0.0); }, {"playback rate"});
}

// A 4-D NIfTI of spheres growing with t: writeNifti's 3-D file with the
// time points after the first appended and dim[0], dim[4] set.
std::filesystem::path writeSeries(const test::TempDir& dir, int count) {
  const auto path = dir / "series.nii";
  std::vector<Volume> volumes;
  for (int t = 0; t < count; ++t) {
    volumes.push_back(makeProcedural("gen:sphere:24"));
    Volume& v = volumes.back();
    for (std::size_t i = 0; i < v.voxelCount(); ++i) {
      v.setValueAtIndex(i, std::min(255.0, v.valueAtIndex(i) * (0.4 + 0.03 * t)));
    }
  }
  writeNifti(volumes[0], path);
  const std::uint64_t size = std::filesystem::file_size(path);
  const std::uint64_t bytes = volumes[0].byteSize();
  EXPECT_GE(size, bytes);
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  const std::int16_t dims[2] = {4, static_cast<std::int16_t>(count)};
  f.seekp(40);  // dim[0]
  f.write(reinterpret_cast<const char*>(&dims[0]), 2);
  f.seekp(48);  // dim[4]
  f.write(reinterpret_cast<const char*>(&dims[1]), 2);
  f.seekp(0, std::ios::end);
  for (int t = 1; t < count; ++t) {
    f.write(reinterpret_cast<const char*>(volumes[t].bytes().data()),
            static_cast<std::streamsize>(bytes));
  }
  return path;
}

TEST(SessionSeries, EachTimePointRendersAsThatTimePointReadAloneInTheFirstOnesWindow) {
  const test::TempDir dir;
  const auto path = writeSeries(dir, 6);
  ASSERT_EQ(timePointCount(path.string()), 6);
  Session s("native");
  s.settings().tf = TransferFunction::preset("grey");
  s.openSeries(path.string());
  ASSERT_NE(s.series(), nullptr);
  EXPECT_EQ(s.series()->count(), 6);
  const ValueRange window = s.volume().window();
  for (const int t : {0, 3, 5, 1}) {
    SCOPED_TRACE("time point " + std::to_string(t));
    s.waitTimePoint(t);
    EXPECT_EQ(s.timePoint(), t);
    EXPECT_EQ(s.volume().window().min, window.min);
    EXPECT_EQ(s.volume().window().max, window.max);
    const Image image = s.render(64, 64);
    Session alone("native");
    alone.settings().tf = TransferFunction::preset("grey");
    alone.settings().window = window;
    alone.setVolume(readVolume(path.string(), {.dicomSeries = "", .time = t, .channel = 0}),
                    "alone");
    EXPECT_EQ(image.rgba(), alone.render(64, 64).rgba());
  }
  expectInputError([&] { s.showTimePoint(6); }, {"time point 6", "0..5"});
  Session flat("native");
  const auto one = dir / "one.nii";
  writeNifti(makeProcedural("gen:sphere:8"), one);
  expectInputError([&] { flat.openSeries(one.string()); }, {"one.nii", "not a time series"});
}

// The voxels of `box` in `whole` against `region` (a read of that box):
// how many differ.
int differingInBox(const Volume& whole, const lod::VoxelBox& box, const Volume& region) {
  EXPECT_EQ(region.dims(), box.size());
  int differ = 0;
  for (int z = box.begin.z; z < box.end.z; ++z)
    for (int y = box.begin.y; y < box.end.y; ++y)
      for (int x = box.begin.x; x < box.end.x; ++x) {
        const glm::ivec3 r = glm::ivec3(x, y, z) - box.begin;
        differ += whole.valueAt(x, y, z) != region.valueAt(r.x, r.y, r.z);
      }
  return differ;
}

// Playing a series keeps what the slice views explore: the crosshair and
// the picked box carry over to the next time point, the overview is that
// time point's volume, and a region shown in the 3D view is read again from
// it, the camera staying where the user left it.
TEST(SessionSeries, TheCrosshairAndARegionShownFollowEachTimePoint) {
  const test::TempDir dir;
  const auto path = writeSeries(dir, 4);
  auto alone = [&](int t) {
    return readVolume(path.string(), {.dicomSeries = "", .time = t, .channel = 0});
  };
  Session s("native");
  s.openSeries(path.string());
  s.view();
  s.exploration().explorer().setCrosshair({5, 6, 7});
  s.waitTimePoint(2);
  ASSERT_TRUE(s.exploring()) << "the exploration was dropped with the time point";
  EXPECT_EQ(s.exploration().explorer().crosshair(), glm::ivec3(5, 6, 7));
  EXPECT_EQ(s.exploration().mode(), ExploreMode::Overview);
  const Volume two = alone(2);
  ASSERT_NE(s.exploration().overview(), nullptr);
  EXPECT_EQ(differingInBox(two, {glm::ivec3(0), two.dims()}, *s.exploration().overview()), 0)
      << "the overview is not time point 2";

  const ExploreStep step = s.exploration().pickedRegion(Follow::Fill);
  s.exploration().show(s.view(), step);
  ASSERT_EQ(s.exploration().mode(), ExploreMode::Region);
  EXPECT_EQ(differingInBox(two, step.box, s.view().volume()), 0);
  s.view().camera().azimuthDeg += 25.0;
  s.view().camera().elevationDeg += 10.0;
  const Camera turned = s.view().camera();
  s.waitTimePoint(3);
  ASSERT_TRUE(s.exploring());
  EXPECT_EQ(s.exploration().mode(), ExploreMode::Region);
  ASSERT_TRUE(s.exploration().shown().has_value());
  EXPECT_EQ(s.exploration().shown()->begin, step.box.begin);
  EXPECT_EQ(s.exploration().shown()->end, step.box.end);
  EXPECT_EQ(s.exploration().explorer().crosshair(), glm::ivec3(5, 6, 7));
  const Volume three = alone(3);
  EXPECT_EQ(differingInBox(three, step.box, s.view().volume()), 0)
      << "the region shown is not time point 3's";
  EXPECT_GT(differingInBox(two, step.box, s.view().volume()), 0)
      << "time points 2 and 3 do not differ in the region: the check proves nothing";
  EXPECT_EQ(s.view().camera().azimuthDeg, turned.azimuthDeg);
  EXPECT_EQ(s.view().camera().elevationDeg, turned.elevationDeg);
  EXPECT_EQ(s.view().camera().eye(), turned.eye());
}

TEST(SessionSeries, PlaybackThroughTheSessionShowsEveryTimePoint) {
  const test::TempDir dir;
  const auto path = writeSeries(dir, 5);
  Session s("native");
  s.openSeries(path.string());
  s.playback().setFps(50.0);
  const auto start = std::chrono::steady_clock::now();
  auto nowMs = [&] {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
  };
  s.playback().play(nowMs());
  std::vector<int> sequence{s.timePoint()};
  while (sequence.size() < 11 && nowMs() < 10000.0) {
    const int t = s.stepPlayback(nowMs());
    if (t != sequence.back()) sequence.push_back(t);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_EQ(sequence.size(), 11u) << "playback stalled";
  for (std::size_t i = 1; i < sequence.size(); ++i) {
    EXPECT_EQ(sequence[i], (sequence[i - 1] + 1) % 5) << "skipped at " << i;
  }
}

// A store's time points fetched by a page: each arrives some frames after
// it is asked for. Playback shows every one in order, a time point that
// had not arrived when due shown late (late frames counted), never
// skipped, and the time point shown is always the volume shown.
TEST(SessionSeries, TimePointsThatArriveLateAreShownLateNeverSkipped) {
  Session s("native");
  s.openSeries(
      6, [](int t) { return constant(t); }, "store.ome.zarr", 0, TimeSeries::Reading::OnPump);
  std::vector<int> askedAtFrame(6, -1);
  askedAtFrame[0] = 0;
  int frame = 0;
  s.series()->setArrival(
      [&](int t) {
        if (askedAtFrame[std::size_t(t)] < 0) askedAtFrame[std::size_t(t)] = frame;
        return frame - askedAtFrame[std::size_t(t)] >= 7;  // 7 frames in flight
      },
      2);
  s.playback().setFps(100.0);
  s.playback().play(0.0);
  std::vector<int> sequence{s.timePoint()};
  for (double now = 0.0; sequence.size() < 13 && now < 5000.0; now += 5.0, ++frame) {
    const int t = s.stepPlayback(now);
    EXPECT_EQ(s.volume().valueAt(0, 0, 0), double(t)) << "the volume shown is the time point's";
    if (t != sequence.back()) sequence.push_back(t);
  }
  ASSERT_EQ(sequence.size(), 13u) << "playback stalled";
  for (std::size_t i = 1; i < sequence.size(); ++i) {
    EXPECT_EQ(sequence[i], (sequence[i - 1] + 1) % 6) << "skipped at " << i;
  }
  EXPECT_GT(s.playback().lateFrames(), 0u) << "at 100/s, 7 frames of 5 ms in flight are late";
}

// What the web page does with a dropped 4-D NIfTI: the bytes in memory,
// the series read from them (io's ByteSource overloads) by a reader the
// session keeps; each time point equals the file's read from disk, and an
// OnPump series plays every time point through stepPlayback.
TEST(SessionSeries, ASeriesFromBytesInMemoryPlaysEveryTimePoint) {
  const test::TempDir dir;
  const auto path = writeSeries(dir, 4);
  std::ifstream in(path, std::ios::binary);
  const std::vector<char> raw((std::istreambuf_iterator<char>(in)), {});
  std::vector<std::byte> bytes(raw.size());
  std::memcpy(bytes.data(), raw.data(), raw.size());
  auto files = std::make_shared<MemoryFiles>();
  files->add("series.nii", std::move(bytes));
  const auto file = files->open("series.nii");
  ASSERT_EQ(timePointCount(*file), 4);
  for (int t = 0; t < 4; ++t) {
    EXPECT_TRUE(std::ranges::equal(readTimePoint(*files->open("series.nii"), *files, t).bytes(),
                                   readTimePoint(path.string(), t).bytes()))
        << t;
  }
  expectInputError([&] { readTimePoint(*file, *files, 4); }, {"series.nii", "4"});
  Session s("native");
  s.openSeries(
      4, [files](int t) { return readTimePoint(*files->open("series.nii"), *files, t); },
      "series.nii");
  ASSERT_NE(s.series(), nullptr);
  EXPECT_EQ(s.name(), "series.nii");
  // Read as the page without threads reads: one time point per frame.
  Session paged("native");
  paged.openSeries(
      4, [files](int t) { return readTimePoint(*files->open("series.nii"), *files, t); },
      "series.nii", 1, TimeSeries::Reading::OnPump);
  EXPECT_EQ(paged.timePoint(), 1);
  EXPECT_EQ(paged.series()->reading(), TimeSeries::Reading::OnPump);
  expectInputError(
      [&] {
        paged.openSeries(
            4, [files](int t) { return readTimePoint(*files->open("series.nii"), *files, t); },
            "series.nii", 4);
      },
      {"series.nii", "time point 4", "0..3"});
  paged.playback().setFps(100.0);
  paged.playback().play(0.0);
  std::vector<int> sequence{paged.timePoint()};
  for (double now = 0.0; sequence.size() < 9 && now < 5000.0; now += 5.0) {
    const int t = paged.stepPlayback(now);
    if (t != sequence.back()) sequence.push_back(t);
  }
  ASSERT_EQ(sequence.size(), 9u) << "playback stalled";
  for (std::size_t i = 1; i < sequence.size(); ++i) {
    EXPECT_EQ(sequence[i], (sequence[i - 1] + 1) % 4) << "skipped at " << i;
  }
  // A series longer than the budget holds (2 of 8 time points kept): the
  // one shown stays held while the next is read, each read once per loop.
  {
    const auto longer = writeSeries(dir, 8);
    std::ifstream f(longer, std::ios::binary);
    const std::vector<char> raw8((std::istreambuf_iterator<char>(f)), {});
    std::vector<std::byte> bytes8(raw8.size());
    std::memcpy(bytes8.data(), raw8.data(), raw8.size());
    auto files8 = std::make_shared<MemoryFiles>();
    files8->add("long.nii", std::move(bytes8));
    const std::uint64_t one = readTimePoint(longer.string(), 0).byteSize();
    const test::BudgetOverride budget(one * 8 + one / 2);  // a quarter holds 2
    Session tight("native");
    tight.openSeries(
        8, [files8](int t) { return readTimePoint(*files8->open("long.nii"), *files8, t); },
        "long.nii", 0, TimeSeries::Reading::OnPump);
    ASSERT_EQ(tight.series()->keep(), 2);
    tight.playback().setFps(100.0);
    tight.playback().play(0.0);
    std::vector<int> shown{0};
    for (double now = 0.0; shown.size() < 17 && now < 5000.0; now += 5.0) {
      const int t = tight.stepPlayback(now);
      if (t != shown.back()) shown.push_back(t);
    }
    ASSERT_EQ(shown.size(), 17u) << "playback stalled with 2 of 8 time points kept";
    for (std::size_t i = 1; i < shown.size(); ++i) EXPECT_EQ(shown[i], (shown[i - 1] + 1) % 8);
    // Two loops: each time point read about twice, not once per frame.
    EXPECT_LE(tight.series()->readLog().size(), 20u);
  }
  // A time point that cannot be read stops playback with its message
  // instead of holding the one shown for ever.
  Session broken("native");
  broken.openSeries(
      4,
      [files](int t) {
        if (t == 2) throw InputError("series.nii: time point 2 is cut short");
        return readTimePoint(*files->open("series.nii"), *files, t);
      },
      "series.nii", 0, TimeSeries::Reading::OnPump);
  broken.playback().setFps(100.0);
  broken.playback().play(0.0);
  std::string stopped;
  for (double now = 0.0; stopped.empty() && now < 5000.0; now += 5.0) {
    try {
      broken.stepPlayback(now);
    } catch (const InputError& e) {
      stopped = e.what();
    }
  }
  EXPECT_NE(stopped.find("time point 2 could not be read"), std::string::npos) << stopped;
  EXPECT_NE(stopped.find("cut short"), std::string::npos) << stopped;
  EXPECT_EQ(broken.timePoint(), 1);
  EXPECT_FALSE(broken.playback().playing());
  // Each time point's image is its own (the volume shown is time point t's).
  for (const int t : {2, 0}) {
    paged.waitTimePoint(t);
    EXPECT_TRUE(std::ranges::equal(paged.volume().bytes(), readTimePoint(path.string(), t).bytes()))
        << t;
  }
}

}  // namespace
}  // namespace tessera::session
