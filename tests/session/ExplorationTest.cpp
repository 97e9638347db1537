// session::Exploration, the one home of the overview / region / grid steps
// both viewers drive: a region's voxels against direct indexing, the camera
// and window across a swap and back, grid moves, refusals and a failed read
// that puts the grid point back, box checks, and the state as JSON.
#include <gtest/gtest.h>

#include <memory>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "support/GpuTestContext.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/session/Exploration.h"
#include "tessera/session/Session.h"
#include "tessera/viewer/Viewer.h"

namespace tessera::session {
namespace {

// Every voxel a different value (mod 251), along a rotated direction so that
// placement in the patient frame is checked, not assumed.
std::shared_ptr<const Volume> hashVolume(glm::ivec3 dims) {
  auto v = std::make_shared<Volume>(Volume::allocate(dims, ScalarType::U8));
  for (std::size_t i = 0; i < v->voxelCount(); ++i) {
    v->setValueAtIndex(i, static_cast<double>((i * 2654435761u >> 7) % 251));
  }
  v->setSpacing({1.0, 1.5, 2.0});
  v->setDirection(glm::dmat3(glm::rotate(glm::dmat4(1.0), 0.3, glm::dvec3(0.0, 0.0, 1.0))));
  v->setOrigin({-10.0, 5.0, 2.0});
  v->setGeometrySource("test");
  v->setWindow({0.0, 250.0});
  return v;
}

constexpr std::uint64_t kBudget = 32ull * 32 * 32;

TEST(Exploration, RegionIsTheBoxOfTheVolumeWhereItLiesAndTheOverviewComesBack) {
  gpu::GlContext& ctx = test::gpuContext();
  const auto volume = hashVolume({40, 32, 24});
  Exploration e(volume, kBudget, "hash");
  viewer::Viewer v(ctx, gpu::DeviceProfile::find("gles3"));
  v.setVolume(Volume(*e.overview()), e.overviewName());
  v.setWindow({20.0, 120.0});
  v.camera().azimuthDeg = 37.0;
  v.camera().zoom = 1.7;
  const Camera overviewCamera = v.camera();

  const lod::VoxelBox box{{6, 16, 4}, {22, 32, 19}};
  e.show(v, e.region(box, Follow::Centre));
  EXPECT_EQ(e.mode(), ExploreMode::Region);
  ASSERT_TRUE(e.shown());
  EXPECT_EQ(e.shown()->begin, box.begin);
  EXPECT_EQ(v.volumeName(), "hash region 6:22,16:32,4:19");
  const Volume& region = v.volume();
  ASSERT_EQ(region.dims(), box.size());
  for (int z = 0; z < box.size().z; ++z) {
    for (int y = 0; y < box.size().y; ++y) {
      for (int x = 0; x < box.size().x; ++x) {
        ASSERT_EQ(region.valueAt(x, y, z),
                  volume->valueAt(x + box.begin.x, y + box.begin.y, z + box.begin.z));
      }
    }
  }
  // Each region voxel sits where the volume's voxel of the same data sits.
  const glm::dvec3 a = region.worldOf(glm::dvec3(3.0, 2.0, 1.0));
  const glm::dvec3 b = volume->worldOf(glm::dvec3(box.begin) + glm::dvec3(3.0, 2.0, 1.0));
  EXPECT_NEAR(glm::length(a - b), 0.0, 1e-9);
  // The user's window and view direction stay; Centre keeps the zoom.
  EXPECT_EQ(v.window().min, 20.0);
  EXPECT_EQ(v.window().max, 120.0);
  EXPECT_DOUBLE_EQ(v.camera().azimuthDeg, 37.0);
  EXPECT_DOUBLE_EQ(v.camera().zoom, 1.7);

  e.showOverview(v, Follow::Back);
  EXPECT_EQ(e.mode(), ExploreMode::Overview);
  EXPECT_FALSE(e.shown());
  EXPECT_EQ(v.volumeName(), "hash");
  EXPECT_EQ(v.volume().dims(), volume->dims());
  EXPECT_EQ(v.camera().target, overviewCamera.target);
  EXPECT_DOUBLE_EQ(v.camera().zoom, overviewCamera.zoom);
  ASSERT_TRUE(e.picked());  // still marked in the overview, red
  const auto lines = e.lines(volume->extent());
  EXPECT_EQ(lines.size(), 12u + 3u);  // the picked box's edges, the crosshair
  EXPECT_EQ(lines.front().color, kRegionColour);
}

TEST(Exploration, GridMovesOneCellRefusesAtTheEdgeAndAFailedReadGoesBack) {
  gpu::GlContext& ctx = test::gpuContext();
  const auto volume = hashVolume({64, 48, 32});
  Exploration e(volume, kBudget, "hash");
  e.setGrid(lod::GridNavigator(e.dims(), glm::ivec3(8)));
  viewer::Viewer v(ctx, gpu::DeviceProfile::find("gles3"));
  v.setVolume(Volume(*e.overview()), e.overviewName());
  const ExploreStep enter = e.enterGrid({30, 20, 14});  // nearest point (4, 3, 2)
  EXPECT_EQ(enter.box.begin, glm::ivec3(24, 16, 8));
  EXPECT_EQ(enter.box.end, glm::ivec3(40, 32, 24));
  e.show(v, enter);
  EXPECT_EQ(e.mode(), ExploreMode::Grid);
  ASSERT_TRUE(e.gridBlock());
  EXPECT_DOUBLE_EQ(v.camera().zoom, 1.0);  // the block fills the view

  // From the front (azimuth 0) Right is -x (the patient's right is on the
  // viewer's left): one cell.
  const auto right = e.move(lod::ViewMove::Right, v.camera().basis());
  ASSERT_TRUE(right);
  EXPECT_EQ(right->box.begin - enter.box.begin, glm::ivec3(-8, 0, 0));
  // Not shown (a store's chunks failed): the point goes back, the block stays.
  e.failed("the block could not be read");
  EXPECT_TRUE(e.refused());
  EXPECT_EQ(e.explorer().grid().point(), glm::ivec3(4, 3, 2));
  EXPECT_EQ(e.gridBlock()->begin, enter.box.begin);
  EXPECT_NE(e.note().find("back at grid point"), std::string::npos) << e.note();

  // At the -x face the next move right is refused with a reason.
  e.explorer().grid().moveTo({0, 3, 2});
  const glm::ivec3 before = e.explorer().grid().point();
  EXPECT_FALSE(e.move(lod::ViewMove::Right, v.camera().basis()));
  EXPECT_TRUE(e.refused());
  EXPECT_EQ(e.explorer().grid().point(), before);
  EXPECT_NE(e.note().find("refused"), std::string::npos) << e.note();
}

TEST(Exploration, BoxesAreClampedAndABadOneNamesTheAxis) {
  Exploration e(hashVolume({40, 32, 24}), kBudget, "hash");
  const lod::VoxelBox b = e.clampBox({{30, 0, 0}, {99, 32, 24}}, "region");
  EXPECT_EQ(b.end, glm::ivec3(40, 32, 24));
  try {
    e.region({{0, 40, 0}, {10, 50, 5}}, Follow::Fill);
    FAIL() << "a box starting outside y was accepted";
  } catch (const InputError& err) {
    EXPECT_STREQ(err.what(), "region: y range 40:50 is empty or starts outside 0:32");
  }
  EXPECT_FALSE(e.picked());
}

TEST(Exploration, StateRoundTripsAndRefusesAnotherVolumesState) {
  const auto volume = hashVolume({40, 32, 24});
  Exploration a(volume, kBudget, "hash");
  a.explorer().setCrosshair({5, 6, 7});
  a.explorer().setRegionSide(16);
  a.setGrid(lod::GridNavigator(a.dims(), glm::ivec3(8)));
  a.enterGrid({20, 20, 10});
  a.region({{1, 2, 3}, {17, 18, 19}}, Follow::Fill);
  const nlohmann::json state = a.state();

  Exploration b(volume, kBudget, "hash");
  b.restore(state);
  EXPECT_EQ(b.state(), state);
  EXPECT_EQ(b.explorer().crosshair(), glm::ivec3(5, 6, 7));
  EXPECT_EQ(b.explorer().grid().cellSize(), glm::ivec3(8));
  EXPECT_EQ(b.picked()->end, glm::ivec3(17, 18, 19));

  Exploration other(hashVolume({16, 16, 16}), kBudget, "small");
  EXPECT_THROW(other.restore(state), InputError);
  nlohmann::json future = state;
  future["version"] = 2;
  EXPECT_THROW(b.restore(future), InputError);
}

// A session saves what is being explored with its settings, and a session
// with the same volume open takes it back.
TEST(Exploration, SessionStateCarriesTheExploration) {
  auto volume = std::make_shared<Volume>(*hashVolume({40, 32, 24}));
  Session a("gles3");
  a.setVolume(volume, "hash");
  EXPECT_TRUE(a.state()["exploration"].is_null());
  a.exploration().explorer().setCrosshair({7, 8, 9});
  a.exploration().region({{2, 2, 2}, {18, 18, 18}}, Follow::Fill);
  EXPECT_EQ(a.exploration().overview()->bytes().data(),
            volume->bytes().data());  // shared, not copied
  const nlohmann::json state = a.state();

  Session b("gles3");
  b.setVolume(volume, "hash");
  b.restore(state);
  EXPECT_EQ(b.exploration().explorer().crosshair(), glm::ivec3(7, 8, 9));
  EXPECT_EQ(b.state()["exploration"], state["exploration"]);
}

// The interactive view is the session's: its volume is the session's
// (shared), what the user sets in it is what state() saves, and another
// session's view restored from that state shows the same region with the
// same camera and look, pixel for pixel.
TEST(Exploration, SessionViewStateRestoresTheSameFrame) {
  auto volume = std::make_shared<Volume>(*hashVolume({40, 32, 24}));
  const lod::VoxelBox box{{2, 2, 2}, {18, 18, 18}};
  const int size = 64;
  auto frame = [&](Session& s) {
    viewer::Viewer& v = s.view();
    v.quality = viewer::Quality::Full;
    gpu::Framebuffer fb =
        gpu::Framebuffer::create(s.device().context->ledger(), "state test", size, size);
    v.render(size, size, fb.id());
    Image img(size, size);
    fb.readRgba8(img.rgba().data());
    return img;
  };

  Session a("gles3");
  a.setVolume(volume, "hash");
  viewer::Viewer& va = a.view();
  EXPECT_EQ(va.volume().bytes().data(), volume->bytes().data());  // shared, not copied
  va.setWindow({10.0, 90.0});
  va.settings().mode = RenderMode::Mip;
  va.camera().azimuthDeg = 41.0;
  a.exploration().show(va, a.exploration().region(box, Follow::Fill));
  va.camera().elevationDeg = -12.0;
  va.camera().zoom = 1.3;
  const nlohmann::json state = a.state();
  const Image shownA = frame(a);  // while a's context is the current one
  EXPECT_EQ(state["settings"]["mode"], "mip");
  EXPECT_EQ(state["exploration"]["mode"], "region");

  Session b("gles3");
  b.setVolume(volume, "hash");
  viewer::Viewer& vb = b.view();
  const Image before = frame(b);
  b.restore(state);
  EXPECT_EQ(vb.volumeName(), va.volumeName());
  EXPECT_EQ(vb.volume().dims(), box.size());
  EXPECT_EQ(vb.window().min, 10.0);
  EXPECT_EQ(vb.window().max, 90.0);
  EXPECT_DOUBLE_EQ(vb.camera().azimuthDeg, 41.0);
  EXPECT_DOUBLE_EQ(vb.camera().elevationDeg, -12.0);
  EXPECT_DOUBLE_EQ(vb.camera().zoom, 1.3);
  EXPECT_EQ(b.currentSettings().toJson(), a.currentSettings().toJson());
  const Image shownB = frame(b);
  EXPECT_EQ(shownA.rgba(), shownB.rgba());
  EXPECT_NE(before.rgba(), shownB.rgba());
}

// The zoom swap lives as long as the exploration says: made from the
// overview when wanted with two stages or more, kept while the stages are the
// same, ended by any other step and not made outside the overview.
TEST(Exploration, ZoomSwapEndsWithAnyOtherStep) {
  gpu::GlContext& ctx = test::gpuContext();
  auto volume = std::make_shared<Volume>(*hashVolume({64, 64, 64}));
  auto source = std::make_shared<const lod::InCoreMultiresSource>(volume);
  Exploration e(source, 16ull * 16 * 16, 32ull * 32 * 32, "hash");
  ASSERT_EQ(e.overviewLevel(), 1);
  viewer::Viewer v(ctx, gpu::DeviceProfile::find("gles3"));
  v.setVolume(Volume(*e.overview()), e.overviewName());
  const std::vector<lod::ZoomStage> stages = viewer::zoomStagesFor(e.explorer(), 1, 400.0);
  ASSERT_GE(stages.size(), 2u);
  e.keepZoom(ctx, false, stages, "a");
  EXPECT_EQ(e.zoom(), nullptr);
  e.keepZoom(ctx, true, {stages.front()}, "one");
  EXPECT_EQ(e.zoom(), nullptr);
  e.keepZoom(ctx, true, stages, "a");
  const viewer::ZoomSwap* made = e.zoom();
  ASSERT_NE(made, nullptr);
  e.keepZoom(ctx, true, stages, "a");
  EXPECT_EQ(e.zoom(), made);  // the same stages: the same swap
  gpu::Framebuffer fb = gpu::Framebuffer::create(ctx.ledger(), "zoom test", 32, 32);
  e.zoomFrame(v, 0.0, 32, 32, fb.id());
  EXPECT_EQ(e.zoom()->shownStage(), e.zoom()->policy().frame().stage);

  e.show(v, e.region({{0, 0, 0}, {16, 16, 16}}, Follow::Fill));
  EXPECT_EQ(e.zoom(), nullptr);
  e.keepZoom(ctx, true, stages, "a");
  EXPECT_EQ(e.zoom(), nullptr);  // not made while a region is shown
  e.showOverview(v, Follow::Back);
  e.keepZoom(ctx, true, stages, "a");
  EXPECT_NE(e.zoom(), nullptr);
  e.showOverview(v, Follow::Keep);
  EXPECT_EQ(e.zoom(), nullptr);
  EXPECT_THROW(e.zoomFrame(v, 0.0, 32, 32, fb.id()), InputError);
}

// A volume handed over in memory is explored as one level until the zoom
// swap needs coarser ones: makeLevels makes them once and keeps what the
// user set (crosshair, region side, grid cell and point, picked region).
TEST(Exploration, LevelsAreMadeForTheZoomSwapKeepingTheUsersState) {
  gpu::GlContext& ctx = test::gpuContext();
  Exploration e(hashVolume({64, 48, 40}), 16ull * 16 * 16, "hash");
  EXPECT_EQ(e.explorer().source().levelCount(), 1);
  e.explorer().setCrosshair({9, 10, 11});
  e.explorer().setRegionSide(12);
  e.setGrid(lod::GridNavigator({64, 48, 40}, glm::ivec3(16)));
  e.enterGrid({40, 30, 20});
  e.pick(lod::VoxelBox{{1, 2, 3}, {11, 12, 13}});
  const nlohmann::json before = e.state();
  e.makeLevels();
  EXPECT_GE(e.explorer().source().levelCount(), 3);
  EXPECT_EQ(e.state(), before);
  EXPECT_EQ(e.overview()->dims(), glm::ivec3(64, 48, 40));  // still the volume itself, level 0
  const auto stages = viewer::zoomStagesFor(e.explorer(), 0, 400.0);
  EXPECT_GE(stages.size(), 2u);
  e.keepZoom(ctx, true, stages, "a");
  ASSERT_NE(e.zoom(), nullptr);
  e.makeLevels();  // a no-op now: the swap stays
  EXPECT_NE(e.zoom(), nullptr);
}

}  // namespace
}  // namespace tessera::session
