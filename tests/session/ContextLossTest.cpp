// A session whose GPU context is lost and made again on a new one
// (Session::loseContext, restoreContext, showRegionAgain: what the web page
// does when the browser takes its WebGL context away and gives it back):
// the view's frame after equals the frame before, pixel for pixel, for a
// volume in memory with its look and the view's knobs away from their
// defaults, a region and a grid block of it, a region of a store the front
// end draws itself whose chunks were let go while the context was lost
// (read again before it shows), a store's channels shown together, and a
// store's t axis the front end plays over bricks (the series and the time
// point it showed kept, playing on in order).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/ChannelStore.h"
#include "support/TestSupport.h"
#include "support/TimeStore.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/DeviceSession.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/ZarrWriter.h"
#include "tessera/lod/ZarrMultiresSource.h"
#include "tessera/session/Session.h"

namespace tessera::session {
namespace {

constexpr int kSize = 64;
constexpr const char* kProfile = "gles3";

// The view's frame as the front end shows it.
Image viewFrame(Session& s) {
  viewer::Viewer& v = s.view();
  gpu::Framebuffer fb =
      gpu::Framebuffer::create(s.device().context->ledger(), "context loss test", kSize, kSize);
  v.render(kSize, kSize, fb.id());
  Image img(kSize, kSize);
  fb.readRgba8(img.rgba().data());
  return img;
}

int differingPixels(const Image& a, const Image& b) {
  int n = 0;
  for (std::size_t p = 0; p < a.rgba().size() / 4; ++p) {
    for (int k = 0; k < 4; ++k) {
      if (a.rgba()[4 * p + k] != b.rgba()[4 * p + k]) {
        ++n;
        break;
      }
    }
  }
  return n;
}

// The fraction of pixels that are not background (the frame shows something).
double litFraction(const Image& img) {
  int lit = 0;
  for (std::size_t p = 0; p < img.rgba().size() / 4; ++p) {
    if (img.rgba()[4 * p] + img.rgba()[4 * p + 1] + img.rgba()[4 * p + 2] > 24) ++lit;
  }
  return double(lit) / (kSize * kSize);
}

// Loses the session's context and restores it onto a new one.
void loseAndRestore(Session& s) {
  s.loseContext();
  ASSERT_TRUE(s.contextLost());
  EXPECT_THROW(s.view(), GpuError);
  EXPECT_THROW(s.render(8, 8), GpuError);
  s.restoreContext(gpu::openDevice(kProfile));
  EXPECT_FALSE(s.contextLost());
}

void expectSameFrame(const Image& before, const Image& after, const char* what) {
  const int differ = differingPixels(before, after);
  std::printf("%s: %d of %d pixels differ after the context was lost and restored; %.1f %% lit\n",
              what, differ, kSize * kSize, 100.0 * litFraction(after));
  EXPECT_EQ(differ, 0) << what;
  EXPECT_GT(litFraction(before), 0.05) << what;
}

// The volume in memory with settings and knobs away from their defaults;
// then a region of it, then a grid block: each lost and restored.
TEST(ContextLoss, VolumeRegionAndGridBlockComeBackIdentical) {
  auto volume = std::make_shared<Volume>(makeSheppLogan({48, 40, 32}));
  Session s(kProfile);
  s.setVolume(volume, "phantom");
  viewer::Viewer& v = s.view();
  v.quality = viewer::Quality::Full;
  v.showAxes = false;
  v.maxVolumePixels = 48 * 48;
  v.clipPlaneFollowsCamera = true;
  v.followingPlaneDistance = 6.0;
  v.setWindow({10.0, 200.0});
  v.settings().shading.enabled = true;
  v.camera().azimuthDeg = 35.0;
  v.camera().elevationDeg = 12.0;
  v.camera().zoom = 1.25;
  const nlohmann::json state = s.state();
  const Image before = viewFrame(s);
  loseAndRestore(s);
  viewer::Viewer& w = s.view();
  EXPECT_EQ(w.volume().bytes().data(), volume->bytes().data());  // shared, not read again
  EXPECT_EQ(w.quality, viewer::Quality::Full);
  EXPECT_FALSE(w.showAxes);
  EXPECT_EQ(w.maxVolumePixels, 48 * 48);
  EXPECT_TRUE(w.clipPlaneFollowsCamera);
  EXPECT_EQ(w.followingPlaneDistance, 6.0);
  EXPECT_EQ(s.state(), state);
  expectSameFrame(before, viewFrame(s), "volume in memory");

  Exploration& e = s.exploration();
  e.show(w, e.region({{6, 10, 4}, {30, 34, 24}}, Follow::Fill));
  w.camera().azimuthDeg = 50.0;
  const Camera overviewCamera = e.overviewCamera();
  const std::string regionName = w.volumeName();
  const Image region = viewFrame(s);
  loseAndRestore(s);
  viewer::Viewer& r = s.view();
  EXPECT_EQ(s.exploration().mode(), ExploreMode::Region);
  EXPECT_EQ(r.volumeName(), regionName);
  EXPECT_FALSE(s.regionAgainPending());
  expectSameFrame(region, viewFrame(s), "a region of it");
  // Back to the overview at the camera it had before the region.
  s.exploration().showOverview(r, Follow::Back);
  EXPECT_EQ(r.camera().azimuthDeg, overviewCamera.azimuthDeg);
  EXPECT_EQ(r.camera().zoom, overviewCamera.zoom);

  Exploration& g = s.exploration();
  g.setGrid(lod::GridNavigator({48, 40, 32}, glm::ivec3(12)));
  g.show(r, g.enterGrid({20, 20, 16}));
  ASSERT_TRUE(g.gridBlock());
  const lod::VoxelBox block = *g.gridBlock();
  const Image grid = viewFrame(s);
  loseAndRestore(s);
  EXPECT_EQ(s.exploration().mode(), ExploreMode::Grid);
  ASSERT_TRUE(s.exploration().gridBlock());
  EXPECT_EQ(s.exploration().gridBlock()->begin, block.begin);
  EXPECT_EQ(s.exploration().gridBlock()->end, block.end);
  expectSameFrame(grid, viewFrame(s), "a grid block of it");
}

// A store's levels whose chunk cache can let them go, as the page's
// (FetchStorage): while let go, prefetch asks for them and says false, and
// a read of them fails.
class LetGoSource final : public lod::MultiresSource {
 public:
  explicit LetGoSource(std::shared_ptr<const lod::MultiresSource> inner)
      : inner_(std::move(inner)) {}
  const Volume& shape() const override { return inner_->shape(); }
  int levelCount() const override { return inner_->levelCount(); }
  lod::LevelInfo levelInfo(int level) const override { return inner_->levelInfo(level); }
  Volume readBox(int level, const lod::VoxelBox& box) const override {
    if (!held) throw Error(describe() + ": chunks of level " + std::to_string(level) + " let go");
    ++reads;
    return inner_->readBox(level, box);
  }
  bool prefetch(int level, const lod::VoxelBox& box) const override {
    (void)level;
    (void)box;
    if (!held) ++asked;
    return held;
  }
  std::string describe() const override { return inner_->describe(); }
  bool held = true;
  mutable int asked = 0;
  mutable int reads = 0;

 private:
  std::shared_ptr<const lod::MultiresSource> inner_;
};

// The page's store over fetch(): the front end draws the pyramid and the
// session explores it; a region of level 0 shown, its chunks let go, the
// context lost and restored: the region is shown again only once its
// chunks are held again, read again, the same frame.
TEST(ContextLoss, StoreRegionWhoseChunksWereLetGoIsReadAgain) {
  test::TempDir dir;
  const std::filesystem::path path = dir.path() / "phantom.ome.zarr";
  OmeZarrWriteOptions options;
  options.chunk = 16;
  writeOmeZarr(makeSheppLogan({64, 64, 48}), path, options);
  auto source = std::make_shared<LetGoSource>(
      std::shared_ptr<const lod::MultiresSource>(lod::ZarrMultiresSource::open(path.string())));
  Session s(kProfile);
  s.drawPyramid(source);
  Exploration& e = s.explore(source, 0, path.string());
  viewer::Viewer& v = s.view();
  v.quality = viewer::Quality::Full;
  v.camera().azimuthDeg = 30.0;
  v.camera().elevationDeg = 15.0;
  const Camera overviewCamera = v.camera();
  e.show(v, e.region({{8, 12, 4}, {40, 44, 36}}, Follow::Fill));
  v.setWindow({5.0, 180.0});
  v.camera().zoom = 1.4;
  const int readsBefore = source->reads;
  const Image before = viewFrame(s);

  source->held = false;  // the cache let them go
  loseAndRestore(s);
  EXPECT_FALSE(s.view().hasVolume());  // the front end draws its store first
  EXPECT_TRUE(s.regionAgainPending());
  EXPECT_FALSE(s.showRegionAgain());
  EXPECT_FALSE(s.showRegionAgain());
  EXPECT_GE(source->asked, 2);
  EXPECT_FALSE(s.view().hasVolume());
  source->held = true;  // the front end fetched them
  EXPECT_TRUE(s.showRegionAgain());
  EXPECT_FALSE(s.regionAgainPending());
  EXPECT_EQ(source->reads, readsBefore + 1);  // read again, once
  viewer::Viewer& w = s.view();
  EXPECT_EQ(s.exploration().mode(), ExploreMode::Region);
  EXPECT_EQ(w.window().min, 5.0);
  EXPECT_EQ(w.window().max, 180.0);
  EXPECT_EQ(w.camera().zoom, 1.4);
  expectSameFrame(before, viewFrame(s), "a store's region, its chunks read again");
  EXPECT_EQ(s.exploration().overviewCamera().azimuthDeg, overviewCamera.azimuthDeg);
  EXPECT_EQ(s.exploration().overviewCamera().zoom, overviewCamera.zoom);
}

// A store's three channels shown together, edited (one hidden, a colour, a
// window), lost and restored: the same channels and the same frame, their
// voxels kept (not read again).
TEST(ContextLoss, ChannelsShownTogetherComeBackIdentical) {
  test::TempDir dir;
  const std::string store = (dir.path() / "three.ome.zarr").string();
  test::writeChannelStore(store, {.dims = {48, 48, 24}});
  Session s(kProfile);
  s.settings().tf = TransferFunction::preset("grey");
  s.settings().render.opacityScale = 20.0;
  s.view().camera().azimuthDeg = 30.0;
  s.view().camera().elevationDeg = 20.0;
  ChannelView& c = s.channelView();
  ASSERT_TRUE(c.open(store));
  c.setVisible(1, false);
  c.setColor(0, {1.0, 1.0, 0.0});
  c.setWindow(2, {100.0, 2000.0});
  c.render(kSize, kSize);
  const Image before = c.readImage();
  const nlohmann::json channels = s.state()["settings"]["channels"];
  loseAndRestore(s);
  ChannelView& after = s.channelView();
  ASSERT_TRUE(after.isOpen());
  EXPECT_EQ(after.name(), store);
  EXPECT_FALSE(after.channels()[1].visible);
  EXPECT_EQ(after.channels()[2].window.max, 2000.0);
  EXPECT_EQ(s.state()["settings"]["channels"], channels);
  std::filesystem::remove_all(store);  // nothing is read again
  after.render(kSize, kSize);
  expectSameFrame(before, after.readImage(), "three channels, one hidden, edited");
}

// The page's store with a t axis played over bricks
// (Session::drawStreamedSeries; frontends/web/src/WebSessionTime.cpp): the
// context lost while time point 3 is shown and playback runs. After the
// restore the session still draws time point 3's pyramid (the same one, not
// read again), the series and its playback are kept, and playback goes on
// from there in order, none skipped; the front end, whose store view is
// made again, draws what drawnPyramid() says.
TEST(ContextLoss, SeriesTheFrontEndDrawsKeepsItsTimePointAndPlaysOn) {
  const test::TempDir dir;
  const std::string store = test::writeTimeStore(dir.path(), 5, 1).string();
  Session s(kProfile);
  s.setVolume(std::make_shared<Volume>(makeSheppLogan({32, 32, 32})), "phantom");
  std::map<int, std::shared_ptr<const lod::MultiresSource>> opened;
  int opens = 0;
  constexpr std::uint64_t kN = test::kTimeStoreSide;
  constexpr std::uint64_t kWarm = kN * kN * kN + (kN / 2) * (kN / 2) * (kN / 2);
  s.drawStreamedSeries(
      5,
      [&](int t) -> std::shared_ptr<const lod::MultiresSource> {
        ++opens;
        return opened[t] = lod::ZarrMultiresSource::open(store, {.time = t});
      },
      kWarm, 2 * kWarm, "store", 0, TimeSeries::Reading::OnPump);
  s.series()->setArrival([](int) { return true; }, 1);
  ASSERT_FALSE(s.showTimePoint(3));  // read on the next pump
  ASSERT_TRUE(s.series()->pump());
  ASSERT_TRUE(s.showTimePoint(3));
  s.playback().setFps(20.0);
  s.playback().play(0.0);
  const auto* shown = s.drawnPyramid().get();
  ASSERT_EQ(shown, opened.at(3).get());
  const int opensBefore = opens;
  const Image before = viewFrame(s);

  loseAndRestore(s);
  ASSERT_NE(s.series(), nullptr);
  EXPECT_EQ(s.series()->count(), 5);
  EXPECT_EQ(s.timePoint(), 3);
  EXPECT_EQ(s.drawnPyramid().get(), shown);  // the same pyramid, not opened again
  EXPECT_EQ(opens, opensBefore);
  EXPECT_TRUE(s.playback().playing());
  expectSameFrame(before, viewFrame(s), "the session's own view beside a series over bricks");

  // Playing on: each time point once its frame is done, in order.
  std::vector<int> sequence{s.timePoint()};
  double now = 1000.0;
  for (int frame = 0; frame < 40 && sequence.size() < 6; ++frame) {
    now += 100.0;
    const int t = s.stepPlayback(now, true);
    if (t == sequence.back()) continue;
    sequence.push_back(t);
    EXPECT_EQ(s.drawnPyramid().get(), opened.at(t).get()) << "time point " << t;
  }
  EXPECT_EQ(sequence, (std::vector<int>{3, 4, 0, 1, 2, 3}));
  std::printf(
      "a series over bricks lost at time point 3: played on %zu time points after the restore\n",
      sequence.size() - 1);
}

}  // namespace
}  // namespace tessera::session
