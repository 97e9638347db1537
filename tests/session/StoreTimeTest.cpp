// A store's t axis streamed over bricks and played with its channels: a
// generated OME-Zarr store (5 time points of 64^3, a bright cube whose x
// moves with t, in a dim sphere; a second channel's cube moves in y). Each
// time point rendered from bricks equals the same time point read in core;
// playback through the session shows every time point once, in order, and
// each frame is that time point's alone (a brick left from the time point
// before would move the cube back); channels and time play together.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "support/TestSupport.h"
#include "tessera/io/ZarrChannels.h"
#include "tessera/lod/ReadLevel.h"
#include "tessera/lod/ZarrMultiresSource.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/session/Session.h"

namespace tessera::session {
namespace {

constexpr int kN = 64;
constexpr int kChunk = 32;

void writeText(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

// Voxel (x, y, z) of channel c at time t: a dim smooth sphere shell and a
// bright 8^3 cube, moving along x (channel 0) or y (channel 1) with t.
std::uint8_t voxel(int x, int y, int z, int t, int c) {
  const double r =
      std::sqrt((x - 31.5) * (x - 31.5) + (y - 31.5) * (y - 31.5) + (z - 31.5) * (z - 31.5)) - 24.0;
  double v = 50.0 * std::exp(-(r / 2.0) * (r / 2.0));
  const int m = 8 + 10 * t;  // the moving axis's first voxel
  const int along = c == 0 ? x : y;
  const int across = c == 0 ? y : x;
  if (along >= m && along < m + 8 && across >= 28 && across < 36 && z >= 28 && z < 36) v = 220.0;
  return static_cast<std::uint8_t>(std::lround(v));
}

// NGFF 0.4 on Zarr v2, uncompressed: level 0 (64^3, 32^3 chunks) and
// level 1 (its 2x2x2 mean), axes t[, c], z, y, x, an omero window 0..255.
std::filesystem::path writeStore(const std::filesystem::path& dir, int times, int channels) {
  const auto root = dir / (channels > 1 ? "tc.ome.zarr" : "t.ome.zarr");
  const bool hasC = channels > 1;
  writeText(root / ".zgroup", R"({"zarr_format": 2})");
  const std::string ones = hasC ? "1.0, 1.0, " : "1.0, ";
  std::string omero;
  for (int c = 0; c < channels; ++c) {
    omero += std::string(c ? ", " : "") + R"({"label": "ch)" + std::to_string(c) +
             R"(", "color": ")" + (c ? "00FF00" : "FF00FF") +
             R"(", "active": true, "window": {"start": 0, "end": 255, "min": 0, "max": 255}})";
  }
  writeText(root / ".zattrs",
            std::string(R"({"multiscales": [{"version": "0.4", "type": "mean", "axes": [)") +
                R"({"name": "t", "type": "time"}, )" +
                (hasC ? R"({"name": "c", "type": "channel"}, )" : "") +
                R"({"name": "z", "type": "space", "unit": "millimeter"},)" +
                R"({"name": "y", "type": "space", "unit": "millimeter"},)" +
                R"({"name": "x", "type": "space", "unit": "millimeter"}], "datasets": [)" +
                R"({"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [)" +
                ones + R"(1.0, 1.0, 1.0]}]},)" +
                R"({"path": "1", "coordinateTransformations": [{"type": "scale", "scale": [)" +
                ones + R"(2.0, 2.0, 2.0]}, {"type": "translation", "translation": [)" +
                (hasC ? "0.0, 0.0, " : "0.0, ") + R"(0.5, 0.5, 0.5]}]}]}], )" +
                R"("omero": {"channels": [)" + omero + "]}}");
  for (int level = 0; level < 2; ++level) {
    const int n = kN >> level;
    const std::string lead =
        std::to_string(times) + ", " + (hasC ? std::to_string(channels) + ", " : "");
    const std::string chunkLead = hasC ? "1, 1, " : "1, ";
    writeText(
        root / std::to_string(level) / ".zarray",
        R"({"zarr_format": 2, "shape": [)" + lead + std::to_string(n) + ", " + std::to_string(n) +
            ", " + std::to_string(n) + R"(], "chunks": [)" + chunkLead + "32, 32, 32" +
            R"(], "dtype": "|u1", "compressor": null, "fill_value": 0, "order": "C", "filters": null})");
    for (int t = 0; t < times; ++t) {
      for (int c = 0; c < channels; ++c) {
        for (int cz = 0; cz < n / kChunk; ++cz) {
          for (int cy = 0; cy < n / kChunk; ++cy) {
            for (int cx = 0; cx < n / kChunk; ++cx) {
              std::string bytes(kChunk * kChunk * kChunk, '\0');
              for (int z = 0; z < kChunk; ++z) {
                for (int y = 0; y < kChunk; ++y) {
                  for (int x = 0; x < kChunk; ++x) {
                    const int gx = cx * kChunk + x, gy = cy * kChunk + y, gz = cz * kChunk + z;
                    int v = 0;
                    if (level == 0) {
                      v = voxel(gx, gy, gz, t, c);
                    } else {
                      for (int k = 0; k < 8; ++k) {
                        v +=
                            voxel(2 * gx + (k & 1), 2 * gy + (k >> 1 & 1), 2 * gz + (k >> 2), t, c);
                      }
                      v = (v + 4) / 8;
                    }
                    bytes[static_cast<std::size_t>((z * kChunk + y) * kChunk + x)] =
                        static_cast<char>(v);
                  }
                }
              }
              const std::string key = std::to_string(t) + "." +
                                      (hasC ? std::to_string(c) + "." : "") + std::to_string(cz) +
                                      "." + std::to_string(cy) + "." + std::to_string(cx);
              writeText(root / std::to_string(level) / key, bytes);
            }
          }
        }
      }
    }
  }
  return root;
}

OpenOptions atTime(int t) {
  OpenOptions o;
  o.time = t;
  return o;
}

void useLook(Session& s) {
  s.settings().tf = TransferFunction::preset("grey");
  s.settings().camera.azimuthDeg = 30.0;
  s.settings().camera.elevationDeg = 20.0;
}

// Time point t read in core (layout auto: a 64^3 store fits), rendered.
std::vector<Image> inCoreFrames(const std::string& store, int times, int size) {
  Session s("native");
  useLook(s);
  std::vector<Image> frames;
  for (int t = 0; t < times; ++t) {
    s.open(store, atTime(t));
    EXPECT_FALSE(s.streamed());
    frames.push_back(s.render(size, size));
  }
  return frames;
}

TEST(StoreTime, EachTimePointFromBricksEqualsThatTimePointInCore) {
  const test::TempDir dir;
  const std::string store = writeStore(dir.path(), 5, 1).string();
  const std::vector<Image> inCore = inCoreFrames(store, 5, 96);
  Session s("native");
  useLook(s);
  s.settings().layout = "bricks";
  for (int t = 0; t < 5; ++t) {
    SCOPED_TRACE("time point " + std::to_string(t));
    s.open(store, atTime(t));
    ASSERT_TRUE(s.streamed());
    const Image bricks = s.render(96, 96);
    const double db = psnr(bricks, inCore[static_cast<std::size_t>(t)]);
    std::printf("bricks vs in core, time point %d: %.1f dB\n", t, db);
    EXPECT_GE(db, 45.0);
  }
  // The frames differ by time point (the cube moves), adjacent ones too:
  // the 45 dB above tells a time point from the one before it, so a
  // render that ignored --time, or a stale frame, fails it.
  for (std::size_t t = 1; t < 5; ++t) {
    const double db = psnr(inCore[t], inCore[t - 1]);
    std::printf("in core, time point %zu vs %zu: %.1f dB\n", t, t - 1, db);
    EXPECT_LT(db, 40.0);
  }
}

TEST(StoreTime, PlaybackOverBricksShowsEveryTimePointOnceInOrderNeverStale) {
  const test::TempDir dir;
  const std::string store = writeStore(dir.path(), 5, 1).string();
  const std::vector<Image> inCore = inCoreFrames(store, 5, 64);
  Session s("native");
  useLook(s);
  s.settings().layout = "bricks";
  s.openSeries(store, atTime(0));
  ASSERT_NE(s.streamedSeries(), nullptr);
  ASSERT_NE(s.series(), nullptr);
  EXPECT_TRUE(s.streamed());
  EXPECT_EQ(s.series()->count(), 5);
  s.playback().setFps(20.0);
  const auto start = std::chrono::steady_clock::now();
  auto nowMs = [&] {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
  };
  s.playback().play(nowMs());
  std::vector<int> sequence{s.timePoint()};
  std::vector<double> dbs{psnr(s.render(64, 64), inCore[0])};
  while (sequence.size() < 6 && nowMs() < 15000.0) {
    const int t = s.stepPlayback(nowMs());
    if (t == sequence.back()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      continue;
    }
    sequence.push_back(t);
    // The frame drawn now: from the new time point's bricks only.
    dbs.push_back(psnr(s.render(64, 64), inCore[static_cast<std::size_t>(t)]));
  }
  const double seconds = nowMs() / 1000.0;
  ASSERT_EQ(sequence.size(), 6u) << "playback stalled";
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    EXPECT_EQ(sequence[i], static_cast<int>(i % 5)) << "at " << i;
    EXPECT_GE(dbs[i], 45.0) << "time point " << sequence[i] << " showed another's bricks";
    std::printf("played time point %d: %.1f dB against it in core\n", sequence[i], dbs[i]);
  }
  std::printf("%zu time points in %.2f s (%.1f tp/s, %llu late frames)\n", sequence.size() - 1,
              seconds, (sequence.size() - 1) / seconds,
              static_cast<unsigned long long>(s.playback().lateFrames()));
  // Read ahead within the budget: each warmed time point's levels, both
  // (64^3 + 32^3 bytes fit), coarsest first.
  const auto warmed = s.streamedSeries()->warmedLevels();
  ASSERT_FALSE(warmed.empty());
  EXPECT_EQ(warmed.front(), (std::vector<int>{1, 0}));
  EXPECT_EQ(StreamedSeries::levelsWithin(*s.pyramid(), 32 * 32 * 32), (std::vector<int>{1}));
}

TEST(StoreTime, ChannelsAndTimePlayTogether) {
  const test::TempDir dir;
  const std::string store = writeStore(dir.path(), 4, 2).string();
  Session s("native");
  useLook(s);
  ChannelView& view = s.channelView();
  ASSERT_TRUE(view.open(store, 0));
  ASSERT_NE(view.series(), nullptr);
  ASSERT_EQ(view.channels().size(), 2);
  EXPECT_EQ(s.series()->count(), 4);
  s.playback().setFps(20.0);
  const auto start = std::chrono::steady_clock::now();
  auto nowMs = [&] {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
  };
  s.playback().play(nowMs());
  std::vector<int> sequence{s.timePoint()};
  view.render(48, 48);
  std::map<int, Image> shown{{0, view.readImage()}};
  while (sequence.size() < 5 && nowMs() < 15000.0) {
    const int t = s.stepPlayback(nowMs());
    if (t == sequence.back()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      continue;
    }
    sequence.push_back(t);
    EXPECT_EQ(view.timePoint(), t);
    // Every channel shown is time point t's: voxel for voxel.
    const ChannelSet direct = readZarrChannels(store, {}, t);
    for (int c = 0; c < 2; ++c) {
      const Volume& a = *view.channels()[c].volume;
      const Volume& b = *direct[c].volume;
      ASSERT_EQ(a.dims(), b.dims());
      EXPECT_EQ(std::memcmp(a.bytes().data(), b.bytes().data(), a.byteSize()), 0)
          << "channel " << c << " of time point " << t << " is another time point's";
    }
    view.render(48, 48);
    shown.emplace(t, view.readImage());
  }
  ASSERT_EQ(sequence.size(), 5u) << "playback stalled";
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    EXPECT_EQ(sequence[i], static_cast<int>(i % 4)) << "at " << i;
  }
  // The frames differ by time point, and each equals that time point
  // opened alone.
  Session alone("native");
  useLook(alone);
  for (int t : {1, 3}) {
    ASSERT_TRUE(alone.channelView().open(store, t));
    alone.channelView().render(48, 48);
    const double db = psnr(alone.channelView().readImage(), shown.at(t));
    std::printf("channels at time point %d played vs opened alone: %.1f dB\n", t, db);
    EXPECT_GE(db, 45.0);
  }
  EXPECT_LT(psnr(shown.at(0), shown.at(1)), 40.0);
  EXPECT_LT(psnr(shown.at(2), shown.at(3)), 40.0);
}

// Channels of time point t from bricks: the frame against its reference.
TEST(StoreTime, ChannelsOfATimePointFromBricksMatchTheReference) {
  const test::TempDir dir;
  const std::string store = writeStore(dir.path(), 4, 2).string();
  Session s("native");
  useLook(s);
  s.settings().layout = "bricks";
  for (int t : {0, 3}) {
    const ChannelFrame f = s.renderChannels(store, 64, 64, true, t);
    std::printf("channels from bricks, time point %d: %.1f dB (%s)\n", t, f.psnr, f.layout.c_str());
    EXPECT_GE(f.psnr, 40.0);
  }
}

// Level 0 of a pyramid, its bytes.
std::vector<std::uint8_t> levelZero(const lod::MultiresSource& source) {
  const Volume v = lod::readLevel(source, 0);
  const auto* p = reinterpret_cast<const std::uint8_t*>(v.bytes().data());
  return {p, p + v.byteSize()};
}

// The page's store over fetch() (frontends/web/src/WebSessionTime.cpp):
// the front end opens each time point's pyramid and draws it itself, its
// reads never wait. Here the "fetched" time points are a set the test
// fills: a time point is shown only once its bytes arrived and it was read
// (a jump too), the drawn pyramid is that time point's, the session's own
// volume stays, and playback holds a time point whose frame the front end
// has not finished (counted late), never skipping one.
TEST(StoreTime, ASeriesTheFrontEndDrawsShowsATimePointOnlyOnceItArrived) {
  const test::TempDir dir;
  const std::string store = writeStore(dir.path(), 5, 1).string();
  Session s("native");
  s.open("gen:sphere:16");
  std::map<int, std::shared_ptr<const lod::MultiresSource>> opened;
  std::set<int> arrived{0};
  std::vector<int> asked;
  constexpr std::uint64_t kWarm = kN * kN * kN + (kN / 2) * (kN / 2) * (kN / 2);
  s.drawStreamedSeries(
      5,
      [&](int t) -> std::shared_ptr<const lod::MultiresSource> {
        std::shared_ptr<const lod::MultiresSource> p =
            lod::ZarrMultiresSource::open(store, {.time = t});
        opened[t] = p;
        return p;
      },
      kWarm, 2 * kWarm, "store", 0, TimeSeries::Reading::OnPump);
  s.series()->setArrival(
      [&](int t) {
        if (!arrived.count(t)) asked.push_back(t);
        return arrived.count(t) > 0;
      },
      1);
  ASSERT_NE(s.series(), nullptr);
  EXPECT_EQ(s.series()->count(), 5);
  EXPECT_EQ(s.series()->keep(), 2);              // what the front end's fetched bytes hold
  EXPECT_EQ(s.volume().dims(), glm::ivec3(16));  // the session's own volume stays
  EXPECT_FALSE(s.streamed());
  ASSERT_NE(s.drawnPyramid(), nullptr);
  EXPECT_EQ(s.drawnPyramid().get(), opened.at(0).get());
  EXPECT_EQ(s.timePoint(), 0);

  // A jump to a time point not fetched: asked for, not shown.
  EXPECT_FALSE(s.showTimePoint(3));
  EXPECT_FALSE(s.series()->pump());
  EXPECT_NE(std::find(asked.begin(), asked.end(), 3), asked.end());
  EXPECT_EQ(s.timePoint(), 0);
  EXPECT_EQ(s.drawnPyramid().get(), opened.at(0).get());
  // Its bytes arrive: read on the pump, then shown, its own voxels drawn.
  arrived.insert(3);
  EXPECT_TRUE(s.series()->pump());
  ASSERT_TRUE(s.showTimePoint(3));
  EXPECT_EQ(s.timePoint(), 3);
  EXPECT_EQ(s.drawnPyramid().get(), opened.at(3).get());
  EXPECT_EQ(levelZero(*s.drawnPyramid()),
            levelZero(*lod::ZarrMultiresSource::open(store, {.time = 3})));
  EXPECT_THROW(s.showTimePoint(5), InputError);

  // Playback with every time point fetched; the front end finishes each
  // time point's frame on its second frame.
  arrived = {0, 1, 2, 3, 4};
  s.playback().setFps(20.0);
  s.playback().play(0.0);
  std::vector<int> sequence{s.timePoint()};
  double now = 0.0;
  int held = 0;  // due frames whose shown time point was not finished
  for (int frame = 0; frame < 60 && sequence.size() < 8; ++frame) {
    now += 100.0;  // every frame is past the 50 ms period
    const bool complete = frame % 2 == 1;
    const int t = s.stepPlayback(now, complete);
    if (!complete) ++held;
    if (t == sequence.back()) continue;
    EXPECT_TRUE(complete) << "time point " << sequence.back() << " left before its frame was done";
    sequence.push_back(t);
    EXPECT_EQ(s.drawnPyramid().get(), opened.at(t).get()) << "time point " << t;
  }
  EXPECT_EQ(sequence, (std::vector<int>{3, 4, 0, 1, 2, 3, 4, 0}));
  EXPECT_EQ(s.playback().advances(), 7u);
  EXPECT_GE(s.playback().lateFrames(), static_cast<std::uint64_t>(held) - 1);
  std::printf("front end's series: %zu shown, %llu late frames (%d held for their frame)\n",
              sequence.size(), static_cast<unsigned long long>(s.playback().lateFrames()), held);

  // The front end draws another pyramid (or none): the series ends.
  s.drawPyramid(nullptr);
  EXPECT_EQ(s.series(), nullptr);
  EXPECT_EQ(s.timePoint(), 0);
  EXPECT_EQ(s.volume().dims(), glm::ivec3(16));
}

// The page's channels of a store with a t axis: a time point's channels
// are read once all their bytes arrived (the arrival the page gives), and
// shown together.
TEST(StoreTime, ChannelsTheCallerReadsPlayOnceTheirBytesArrived) {
  const test::TempDir dir;
  const std::string store = writeStore(dir.path(), 4, 2).string();
  Session s("native");
  useLook(s);
  std::set<int> arrived{0};
  std::vector<int> asked;
  ChannelView& view = s.channelView();
  view.showSeries(
      4, readZarrChannels(store, {}, 0), [&](int t) { return readZarrChannels(store, {}, t); },
      "store", 0, TimeSeries::Reading::OnPump,
      [&](int t) {
        if (!arrived.count(t)) asked.push_back(t);
        return arrived.count(t) > 0;
      },
      1);
  ASSERT_NE(s.series(), nullptr);
  EXPECT_EQ(s.series()->count(), 4);
  EXPECT_EQ(view.channels().size(), 2);
  EXPECT_FALSE(s.showTimePoint(2));
  EXPECT_FALSE(s.series()->pump());
  EXPECT_NE(std::find(asked.begin(), asked.end(), 2), asked.end());
  EXPECT_EQ(s.timePoint(), 0);
  arrived.insert(2);
  EXPECT_TRUE(s.series()->pump());
  ASSERT_TRUE(s.showTimePoint(2));
  EXPECT_EQ(s.timePoint(), 2);
  const ChannelSet direct = readZarrChannels(store, {}, 2);
  for (int c = 0; c < 2; ++c) {
    const Volume& a = *view.channels()[c].volume;
    const Volume& b = *direct[c].volume;
    ASSERT_EQ(a.dims(), b.dims());
    EXPECT_EQ(std::memcmp(a.bytes().data(), b.bytes().data(), a.byteSize()), 0)
        << "channel " << c << " is another time point's";
  }
  EXPECT_THROW(view.showSeries(1, readZarrChannels(store, {}, 0), nullptr, "store", 0), InputError);
}

}  // namespace
}  // namespace tessera::session
