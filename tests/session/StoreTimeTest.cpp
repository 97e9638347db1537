// A store's t axis streamed over bricks and played with its channels: a
// generated OME-Zarr store (5 time points of 64^3, a bright cube whose x
// moves with t, in a dim sphere; a second channel's cube moves in y). Each
// time point rendered from bricks equals the same time point read in core;
// playback through the session shows every time point once, in order, and
// each frame is that time point's alone (a brick left from the time point
// before would move the cube back); channels and time play together.
#include <gtest/gtest.h>

#include <algorithm>
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

#include "support/ChannelStore.h"
#include "support/TestSupport.h"
#include "support/TimeStore.h"
#include "tessera/io/ZarrChannels.h"
#include "tessera/lod/ReadLevel.h"
#include "tessera/lod/ZarrMultiresSource.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/session/Session.h"

namespace tessera::session {
namespace {

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
  const std::string store = test::writeTimeStore(dir.path(), 5, 1).string();
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
  const std::string store = test::writeTimeStore(dir.path(), 5, 1).string();
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

// What a front end with a view (the desktop viewer) plays: a store opened
// in the view over bricks, its frames drawn by streamedFrames() one step
// per front-end frame. Playback moves on only once the time point shown
// has been drawn complete, so every time point's complete frame is shown,
// in order, each equal to that time point in core; every time point is
// streamed into the one layout made for the first (its atlas, page table
// and technique kept on the GPU).
struct ShownOverBricks {
  std::vector<int> sequence;  // time points drawn complete, in the order shown
  std::vector<Image> frames;
  std::vector<std::uint64_t> textureBytes;        // the ledger at each
  std::vector<std::size_t> textures;              // textures and buffers held at each
  std::vector<unsigned> frameTextures;            // the GL name of the frame shown
  std::vector<const gpu::Texture*> frameObjects;  // and the object holding it
};

ShownOverBricks playInView(Session& s, int shows, int size) {
  ShownOverBricks shown;
  s.playback().setFps(30.0);
  const auto start = std::chrono::steady_clock::now();
  auto nowMs = [&] {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
  };
  s.playback().play(nowMs());
  int show = 0;  // the how-manieth time point shown
  const gpu::MemoryLedger& ledger = s.device().context->ledger();
  while (static_cast<int>(shown.sequence.size()) < shows && nowMs() < 20000.0) {
    const int before = s.timePoint();
    const int t = s.stepPlayback(nowMs());
    if (t != before) ++show;
    StreamedFrames& frames = s.streamedFrames();
    frames.render(size, size);  // the front end's frame
    if (static_cast<int>(shown.sequence.size()) == show && frames.shownComplete(t)) {
      shown.sequence.push_back(t);
      shown.frames.push_back(frames.readImage());
      shown.textureBytes.push_back(ledger.totalBytes());
      shown.textures.push_back(ledger.count());
      const gpu::Texture& frame = frames.render(size, size);  // complete: drawn already
      shown.frameTextures.push_back(frame.id());
      shown.frameObjects.push_back(&frame);
    }
  }
  return shown;
}

// The view's look as useLook's (the view frames its camera anew at open).
void useLookInView(Session& s) {
  s.view().camera().azimuthDeg = 30.0;
  s.view().camera().elevationDeg = 20.0;
  s.view().tfEditor().setTransferFunction(TransferFunction::preset("grey"));
}

TEST(StoreTime, ViewPlaysOverBricksEveryTimePointCompleteInOrder) {
  const test::TempDir dir;
  const std::string store = test::writeTimeStore(dir.path(), 5, 1).string();
  const std::vector<Image> inCore = inCoreFrames(store, 5, 64);
  Session s("native");
  s.settings().layout = "bricks";
  s.openInView(store);
  ASSERT_NE(s.streamedSeries(), nullptr);
  ASSERT_TRUE(s.streamed());
  ASSERT_EQ(s.series()->count(), 5);
  useLookInView(s);
  const ShownOverBricks shown = playInView(s, 7, 64);
  ASSERT_EQ(shown.sequence.size(), 7u) << "playback stalled";
  for (std::size_t i = 0; i < shown.sequence.size(); ++i) {
    const int t = shown.sequence[i];
    EXPECT_EQ(t, static_cast<int>(i % 5)) << "at " << i;
    const double own = psnr(shown.frames[i], inCore[static_cast<std::size_t>(t)]);
    double other = 0.0;  // the nearest other time point
    for (int u = 0; u < 5; ++u) {
      if (u != t)
        other = std::max(other, psnr(shown.frames[i], inCore[static_cast<std::size_t>(u)]));
    }
    std::printf(
        "shown %zu: time point %d, %.1f dB against it in core, %.1f against another, %llu "
        "texture bytes\n",
        i, t, own, other, static_cast<unsigned long long>(shown.textureBytes[i]));
    EXPECT_GE(own, 45.0) << "time point " << t;
    EXPECT_LT(other, 40.0) << "time point " << t << " looks like another";
  }
  // One layout, made for the first time point; the six after it streamed
  // into its textures: the same textures held at every time point (their
  // count and bytes), never more in between, and the frame drawn into the
  // same render target by the same technique.
  EXPECT_EQ(s.streamedFrames().layoutsMade(), 1);
  EXPECT_EQ(s.streamedFrames().timePointsStreamedIn(), 6);
  const auto [low, high] =
      std::minmax_element(shown.textureBytes.begin(), shown.textureBytes.end());
  EXPECT_EQ(*low, *high);
  EXPECT_LE(s.device().context->ledger().peakBytes(), *high);
  for (std::size_t i = 1; i < shown.sequence.size(); ++i) {
    EXPECT_EQ(shown.textures[i], shown.textures[0]) << "shown " << i;
    EXPECT_EQ(shown.frameTextures[i], shown.frameTextures[0]) << "shown " << i;
    EXPECT_EQ(shown.frameObjects[i], shown.frameObjects[0]) << "shown " << i;
  }
  std::printf("%llu late time points, %zu textures held throughout (%llu bytes)\n",
              static_cast<unsigned long long>(s.playback().lateTimePoints()), shown.textures[0],
              static_cast<unsigned long long>(*high));
}

// A time point's frame after playing from time point 0 (its bricks streamed
// into the atlas the earlier ones used) against the same time point opened
// alone over bricks and refined to the end (Session::render, what `tessera
// render STORE --time T --layout bricks` draws): the same bricks in other
// slots of the atlas, the same image.
TEST(StoreTime, ATimePointPlayedIntoTheAtlasEqualsItRenderedAlone) {
  const test::TempDir dir;
  const std::string store = test::writeTimeStore(dir.path(), 5, 1).string();
  // ES 3 (one 3D atlas) and ES 2 (the atlas as mosaics of z-slices).
  for (const std::string profile : {"native", "webgl1-desktop-2012"}) {
    SCOPED_TRACE(profile);
    std::vector<Image> alone;
    {
      Session fresh(profile);
      useLook(fresh);
      fresh.settings().layout = "bricks";
      for (int t = 0; t < 5; ++t) {
        fresh.open(store, atTime(t));
        ASSERT_TRUE(fresh.streamed());
        alone.push_back(fresh.render(64, 64));
      }
    }
    Session s(profile);
    s.settings().layout = "bricks";
    s.openInView(store);
    useLookInView(s);
    const ShownOverBricks shown = playInView(s, 6, 64);
    ASSERT_EQ(shown.sequence, (std::vector<int>{0, 1, 2, 3, 4, 0})) << "playback stalled";
    EXPECT_EQ(s.streamedFrames().layoutsMade(), 1);
    for (std::size_t i = 0; i < shown.sequence.size(); ++i) {
      const int t = shown.sequence[i];
      const double db = psnr(shown.frames[i], alone[static_cast<std::size_t>(t)]);
      const double other = psnr(shown.frames[i], alone[static_cast<std::size_t>((t + 1) % 5)]);
      std::printf(
          "%s, shown %zu: time point %d played vs rendered alone over bricks: %.1f dB "
          "(vs the next time point %.1f dB)\n",
          profile.c_str(), i, t, db, other);
      EXPECT_GE(db, 60.0) << "time point " << t;
      EXPECT_LT(other, 40.0) << "time point " << t;
      EXPECT_EQ(shown.textures[i], shown.textures[0]) << "shown " << i;
    }
  }
}

// Three channels with a t axis played over bricks, as `view STORE --bricks`
// plays them (the store opened in the view over bricks, then its channel
// list): every channel of a time point streamed into one atlas (one
// layout for the series), each time point's frame against the CPU
// reference of that time point's channels (Session::renderChannels over
// bricks), and a channel toggled while playback pauses changes only the
// pixels of its own cube. The windows leave the dim shell out, so that
// each channel's footprint is its cube alone.
TEST(StoreTime, ThreeChannelsPlayOverBricksEachTimePointAsItsReference) {
  const test::TempDir dir;
  const std::string store = test::writeTimeStore(dir.path(), 5, 3).string();
  constexpr int kSize = 64;
  const std::vector<ValueRange> windows(3, ValueRange{100.0, 255.0});
  std::vector<ChannelFrame> references;
  {
    Session fresh("native");
    useLook(fresh);
    fresh.settings().layout = "bricks";
    fresh.settings().channels.windows = windows;
    for (int t = 0; t < 5; ++t) {
      references.push_back(fresh.renderChannels(store, kSize, kSize, true, t));
    }
  }
  Session s("native");
  s.settings().layout = "bricks";
  s.settings().channels.windows = windows;
  s.openInView(store);
  ASSERT_NE(s.streamedSeries(), nullptr);
  ChannelView& view = s.channelView();
  ASSERT_TRUE(view.open(store));
  ASSERT_TRUE(view.overBricks());
  ASSERT_EQ(view.channels().size(), 3);
  EXPECT_EQ(view.series(), nullptr);  // the session's streamed series plays them
  ASSERT_EQ(s.streamedChannels().size(), 3u);
  useLookInView(s);
  const ShownOverBricks shown = playInView(s, 6, kSize);
  ASSERT_EQ(shown.sequence, (std::vector<int>{0, 1, 2, 3, 4, 0})) << "playback stalled";
  EXPECT_EQ(s.streamedFrames().layoutsMade(), 1);
  EXPECT_EQ(s.streamedFrames().timePointsStreamedIn(), 5);
  for (std::size_t i = 0; i < shown.sequence.size(); ++i) {
    const int t = shown.sequence[i];
    const ChannelFrame& r = references[static_cast<std::size_t>(t)];
    const double db = psnr(shown.frames[i], *r.reference);
    const double gpu = psnr(shown.frames[i], r.image);
    const double other =
        psnr(shown.frames[i], *references[static_cast<std::size_t>((t + 1) % 5)].reference);
    std::printf(
        "3 channels over bricks, shown %zu: time point %d, %.1f dB against its "
        "reference (%.1f dB against it rendered alone, %.1f against the next time "
        "point's reference)\n",
        i, t, db, gpu, other);
    EXPECT_GE(db, 40.0) << "time point " << t;
    EXPECT_LT(other, db - 10.0) << "time point " << t << " looks like the next";
    EXPECT_EQ(shown.textures[i], shown.textures[0]) << "shown " << i;
  }

  // Paused at time point 3 (the cubes apart), each channel toggled.
  s.playback().pause();
  ASSERT_TRUE(s.showTimePoint(3));
  StreamedFrames& frames = s.streamedFrames();
  auto refined = [&] {
    for (int step = 0; step < 2000; ++step) {
      frames.render(kSize, kSize);
      if (frames.shownComplete(3)) return frames.readImage();
    }
    ADD_FAILURE() << "the frame did not refine";
    return frames.readImage();
  };
  const Image all = refined();
  auto showOnly = [&](int only) {
    for (int c = 0; c < 3; ++c) view.setVisible(c, only < 0 || c == only);
  };
  for (int c = 0; c < 3; ++c) {
    view.setVisible(c, false);
    const Image without = refined();
    showOnly(c);
    const Image alone = refined();
    for (int k = 0; k < 3; ++k) view.setVisible(k, false);
    const Image black = refined();
    showOnly(-1);
    const std::vector<bool> changed = test::differing(all, without, 2);
    const std::vector<bool> cube = test::differing(alone, black, 0);
    int inside = 0, outside = 0;
    for (std::size_t p = 0; p < changed.size(); ++p) {
      if (changed[p]) ++(cube[p] ? inside : outside);
    }
    std::printf(
        "time point 3, channel %d toggled over bricks: %d pixels changed inside its "
        "cube's projection, %d outside\n",
        c, inside, outside);
    EXPECT_GT(inside, 20) << "channel " << c;
    EXPECT_EQ(outside, 0) << "channel " << c;
  }
  EXPECT_EQ(s.streamedFrames().layoutsMade(), 1);  // toggles change uniforms, not textures
}

// A store whose level 0 does not fit a quarter of the host budget plays
// over bricks in the view without being asked (it cannot play in core).
TEST(StoreTime, AStoreBeyondAQuarterOfTheHostBudgetPlaysOverBricksInTheView) {
  const test::TempDir dir;
  const std::string store = test::writeTimeStore(dir.path(), 3, 1).string();
  const std::vector<Image> inCore = inCoreFrames(store, 3, 48);
  const test::BudgetOverride budget(768 * 1024);  // a quarter: 192 KiB; level 0: 256 KiB
  Session s("native");
  s.openInView(store);
  ASSERT_NE(s.streamedSeries(), nullptr);
  ASSERT_EQ(s.series()->count(), 3);
  useLookInView(s);
  const ShownOverBricks shown = playInView(s, 4, 48);
  ASSERT_EQ(shown.sequence, (std::vector<int>{0, 1, 2, 0})) << "playback stalled or skipped";
  for (std::size_t i = 0; i < shown.sequence.size(); ++i) {
    const double db = psnr(shown.frames[i], inCore[static_cast<std::size_t>(shown.sequence[i])]);
    std::printf("host budget 768 KiB, shown %zu: time point %d, %.1f dB against it in core\n", i,
                shown.sequence[i], db);
    EXPECT_GE(db, 45.0);
  }
}

TEST(StoreTime, ChannelsAndTimePlayTogether) {
  const test::TempDir dir;
  const std::string store = test::writeTimeStore(dir.path(), 4, 2).string();
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
  const std::string store = test::writeTimeStore(dir.path(), 4, 2).string();
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
  const std::string store = test::writeTimeStore(dir.path(), 5, 1).string();
  Session s("native");
  s.open("gen:sphere:16");
  std::map<int, std::shared_ptr<const lod::MultiresSource>> opened;
  std::set<int> arrived{0};
  std::vector<int> asked;
  constexpr std::uint64_t kN = test::kTimeStoreSide;
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

// A time point's pyramid whose level-0 chunks arrive when the test says
// (the page's store over fetch(): prefetch lists what it lacks).
class ArrivingSource final : public lod::MultiresSource {
 public:
  ArrivingSource(std::shared_ptr<const lod::MultiresSource> inner, const std::set<int>& arrived,
                 int time)
      : inner_(std::move(inner)), arrived_(arrived), time_(time) {}
  const Volume& shape() const override { return inner_->shape(); }
  int levelCount() const override { return inner_->levelCount(); }
  lod::LevelInfo levelInfo(int level) const override { return inner_->levelInfo(level); }
  Volume readBox(int level, const lod::VoxelBox& box) const override {
    return inner_->readBox(level, box);
  }
  bool prefetch(int level, const lod::VoxelBox& box) const override {
    (void)box;
    if (level > 0 || arrived_.count(time_)) return true;
    ++asked;
    return false;
  }
  std::string describe() const override { return inner_->describe(); }
  mutable int asked = 0;

 private:
  std::shared_ptr<const lod::MultiresSource> inner_;
  const std::set<int>& arrived_;
  int time_;
};

// How many voxels of `box` of time point t's level 0 differ from `shown`.
int differingFrom(const std::string& store, int t, const lod::VoxelBox& box, const Volume& shown) {
  const Volume want = lod::ZarrMultiresSource::open(store, {.time = t})->readBox(0, box);
  EXPECT_EQ(want.dims(), shown.dims());
  if (want.dims() != shown.dims()) return -1;
  int differ = 0;
  for (int z = 0; z < want.dims().z; ++z)
    for (int y = 0; y < want.dims().y; ++y)
      for (int x = 0; x < want.dims().x; ++x)
        differ += want.valueAt(x, y, z) != shown.valueAt(x, y, z);
  return differ;
}

// The region the series tests pick (the cube lies in it at every time
// point), shown in the view from the exploration: how many of its voxels
// differ from time point t's.
const lod::VoxelBox kRegion{{4, 20, 20}, {64, 44, 44}};
int showRegion(Session& s, const std::string& store, int t) {
  Exploration& e = s.exploration();
  e.show(s.view(), e.region(kRegion, Follow::Fill));
  return differingFrom(store, t, kRegion, s.view().volume());
}

// Turns the camera and sets a window, as a user looking at the region; the
// turned camera.
Camera turnAndWindow(Session& s) {
  s.view().camera().azimuthDeg += 25.0;
  s.view().setWindow({10.0, 200.0});
  return s.view().camera();
}

// The region carried over to time point t from `previous`: the same box and
// crosshair (40, 30, 31), t's voxels (not previous's), the turned camera
// and the window kept.
void expectRegionCarriedOver(Session& s, const std::string& store, int t, int previous,
                             const Camera& turned) {
  ASSERT_EQ(s.exploration().mode(), ExploreMode::Region) << "time point " << t;
  ASSERT_TRUE(s.exploration().shown().has_value());
  EXPECT_EQ(s.exploration().shown()->begin, kRegion.begin);
  EXPECT_EQ(s.exploration().shown()->end, kRegion.end);
  EXPECT_EQ(s.exploration().explorer().crosshair(), glm::ivec3(40, 30, 31));
  EXPECT_EQ(differingFrom(store, t, kRegion, s.view().volume()), 0)
      << "the region shown at time point " << t << " is not its own";
  EXPECT_GT(differingFrom(store, previous, kRegion, s.view().volume()), 0)
      << "time points " << previous << " and " << t
      << " do not differ in the box: the check proves nothing";
  EXPECT_EQ(s.view().camera().eye(), turned.eye());
  EXPECT_EQ(s.view().window().min, 10.0);
  EXPECT_EQ(s.view().window().max, 200.0);
}

// The page's store with a t axis played over bricks, explored
// (Session::exploreDrawn): the exploration is of the time point shown, and
// a region shown in the view follows each time point as in core, read
// again from it once its level-0 chunks of that time point have arrived
// (asked for until then: the time point waits, by the slider and in
// playback), the camera and window staying where the user left them.
TEST(StoreTime, ARegionOfASeriesTheFrontEndDrawsFollowsEachTimePointOnceItsChunksArrived) {
  const test::TempDir dir;
  const std::string store = test::writeTimeStore(dir.path(), 5, 1).string();
  Session s("native");
  s.open("gen:sphere:16");
  std::set<int> arrived{0, 1, 2, 3};
  std::map<int, std::shared_ptr<const ArrivingSource>> opened;
  constexpr std::uint64_t kHalf = test::kTimeStoreSide / 2;
  constexpr std::uint64_t kWarm = kHalf * kHalf * kHalf;  // the coarsest level
  s.drawStreamedSeries(
      5,
      [&](int t) -> std::shared_ptr<const lod::MultiresSource> {
        auto p = std::make_shared<const ArrivingSource>(
            lod::ZarrMultiresSource::open(store, {.time = t}), arrived, t);
        opened[t] = p;
        return p;
      },
      kWarm, 2 * kWarm, "store", 0, TimeSeries::Reading::OnPump);
  s.series()->setArrival([](int) { return true; }, 1);
  Exploration& first = s.exploreDrawn("store");
  EXPECT_EQ(&first.explorer().source(), s.drawnPyramid().get());
  first.explorer().setCrosshair({40, 30, 31});

  // Time point 3 by the slider: the exploration follows it.
  ASSERT_FALSE(s.showTimePoint(3));
  ASSERT_TRUE(s.series()->pump());
  ASSERT_TRUE(s.showTimePoint(3));
  ASSERT_TRUE(s.exploring());
  EXPECT_EQ(&s.exploration().explorer().source(), opened.at(3).get());
  EXPECT_EQ(s.exploration().explorer().crosshair(), glm::ivec3(40, 30, 31));
  EXPECT_EQ(s.exploration().mode(), ExploreMode::Overview);

  // A region picked there is time point 3's voxels.
  EXPECT_EQ(showRegion(s, store, 3), 0) << "not time point 3's region";
  const Camera turned = turnAndWindow(s);

  // Time point 4, read ahead, but the region's chunks have not arrived:
  // playback waits (a late frame), the region of time point 3 stays.
  s.playback().setFps(20.0);
  s.playback().play(0.0);
  double now = 0.0;
  for (int frame = 0; frame < 4; ++frame) {
    now += 100.0;
    EXPECT_EQ(s.stepPlayback(now, true), 3) << "frame " << frame;
  }
  ASSERT_TRUE(opened.count(4));
  EXPECT_GT(opened.at(4)->asked, 0) << "the region's chunks of time point 4 were not asked for";
  EXPECT_EQ(s.exploration().mode(), ExploreMode::Region);
  EXPECT_EQ(differingFrom(store, 3, kRegion, s.view().volume()), 0);
  EXPECT_GT(s.playback().lateFrames(), 0u);

  // They arrive: time point 4's region, the same box, camera and window.
  arrived.insert(4);
  now += 100.0;
  ASSERT_EQ(s.stepPlayback(now, true), 4);
  expectRegionCarriedOver(s, store, 4, 3, turned);
  EXPECT_EQ(&s.exploration().explorer().source(), opened.at(4).get());
}

// The desktop's way (`view STORE --bricks`: the store opened in the view
// over bricks, its frames drawn by streamedFrames()): a region picked at a
// time point is that time point's voxels, and playback with it shown moves
// on, the region read again from each time point shown (the same box, the
// camera and window where the user left them), never waiting for a frame
// of the whole volume that the view does not draw while the region is
// shown; back to the overview, the streamed frames play on.
TEST(StoreTime, ARegionShownInTheViewOverBricksFollowsEachTimePoint) {
  const test::TempDir dir;
  const std::string store = test::writeTimeStore(dir.path(), 5, 1).string();
  Session s("native");
  s.settings().layout = "bricks";
  s.openInView(store);
  ASSERT_NE(s.streamedSeries(), nullptr);
  ASSERT_TRUE(s.streamed());
  useLookInView(s);
  s.waitTimePoint(2);
  // The desktop has drawn time point 2's frames over bricks before the pick.
  for (int i = 0; i < 400 && !s.streamedFrames().shownComplete(2); ++i) {
    s.streamedFrames().render(64, 64);
  }
  ASSERT_TRUE(s.streamedFrames().shownComplete(2));
  s.exploration().explorer().setCrosshair({40, 30, 31});
  ASSERT_EQ(showRegion(s, store, 2), 0) << "not time point 2's region";
  const Camera turned = turnAndWindow(s);

  s.playback().setFps(30.0);
  const auto start = std::chrono::steady_clock::now();
  auto nowMs = [&] {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
  };
  s.playback().play(nowMs());
  std::vector<int> shown{2};
  while (shown.size() < 5 && nowMs() < 20000.0) {
    const int t = s.stepPlayback(nowMs());
    if (t == shown.back()) continue;
    shown.push_back(t);
    expectRegionCarriedOver(s, store, t, shown[shown.size() - 2], turned);
    if (::testing::Test::HasFatalFailure()) return;
  }
  EXPECT_EQ(shown, (std::vector<int>{2, 3, 4, 0, 1})) << "playback with a region shown stalled";

  // Back to the overview: the streamed frames of the time point shown play on.
  s.exploration().showOverview(s.view(), Follow::Back);
  ASSERT_EQ(s.exploration().mode(), ExploreMode::Overview);
  const int before = s.timePoint();
  bool moved = false;
  while (!moved && nowMs() < 40000.0) {
    const int t = s.stepPlayback(nowMs());
    s.streamedFrames().render(64, 64);
    moved = t != before;
  }
  EXPECT_TRUE(moved) << "playback stalled after the region";
}

// The page's store whose level 0 fits in core (Session::openSeries of its
// time points, the store's pyramid drawn as well): explored at time point
// 2, a region is time point 2's, not the drawn pyramid's (time point 0).
TEST(StoreTime, ASeriesReadInCoreIsExploredAtTheTimePointShown) {
  const test::TempDir dir;
  const std::string store = test::writeTimeStore(dir.path(), 4, 1).string();
  Session s("native");
  s.drawPyramid(lod::ZarrMultiresSource::open(store, {.time = 0}));
  s.openSeries(
      4,
      [&](int t) { return lod::readLevel(*lod::ZarrMultiresSource::open(store, {.time = t}), 0); },
      "store", 0, TimeSeries::Reading::OnPump);
  s.view();
  ASSERT_FALSE(s.showTimePoint(2));
  while (!s.showTimePoint(2)) ASSERT_TRUE(s.series()->pump());
  Exploration& e = s.exploreDrawn("store");
  const lod::VoxelBox box{{4, 20, 20}, {64, 44, 44}};
  e.show(s.view(), e.region(box, Follow::Fill));
  EXPECT_EQ(differingFrom(store, 2, box, s.view().volume()), 0) << "not time point 2's region";
  EXPECT_GT(differingFrom(store, 0, box, s.view().volume()), 0);
  // Playing on, it follows (Session::showTimePoint in core).
  while (!s.showTimePoint(3)) ASSERT_TRUE(s.series()->pump());
  EXPECT_EQ(s.exploration().mode(), ExploreMode::Region);
  EXPECT_EQ(differingFrom(store, 3, box, s.view().volume()), 0) << "not time point 3's region";
}

// The page's channels of a store with a t axis: a time point's channels
// are read once all their bytes arrived (the arrival the page gives), and
// shown together.
TEST(StoreTime, ChannelsTheCallerReadsPlayOnceTheirBytesArrived) {
  const test::TempDir dir;
  const std::string store = test::writeTimeStore(dir.path(), 4, 2).string();
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
