// The proof that a layout is one class plus one registration: a
// "flipped-mosaic" layout, written and registered here from a static
// initialiser, stores the volume's slices in reverse order in a mosaic and
// samples it through its own sampleVolume() (the z coordinate mirrored
// before the mosaic's lookup). It keeps the trilinear field of the volume's
// voxels, so the CPU reference needs nothing of it; RegistrySuite
// (tests/render/RegistrySuiteTest.cpp) renders it with every technique at
// both API levels with no test edited. The tests here check what the suite
// takes for granted: that it is registered, that it really stores the
// slices reversed, and that it samples the voxels' field.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "support/GpuTestContext.h"
#include "support/TestLayouts.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/LayoutProbe.h"
#include "tessera/layout/LayoutRegistry.h"
#include "tessera/layout/MosaicLayout.h"
#include "tessera/reference/Reconstruction.h"

using namespace tessera;

namespace {

const char* const kName = "flipped-mosaic";

// The mosaic's own sampleVolume() is renamed while its GLSL is included, and
// the layout's wraps it: voxel centre (k + 0.5) / d of the original is
// slice d - 1 - k of the stored copy, at 1 - z.
const char* const kRename = "#define sampleVolume flippedMosaicStoredSample\n";
const char* const kWrapper = R"(
#undef sampleVolume
float sampleVolume(vec3 p) {
  return flippedMosaicStoredSample(vec3(p.x, p.y, 1.0 - p.z));
}
)";

// The volume with its slices in reverse order (spacing and type kept).
Volume flippedInZ(const Volume& v) {
  Volume f = Volume::allocate(v.dims(), v.type(), "flipped copy");
  f.setSpacing(v.spacing());
  const std::size_t slice = v.byteSize() / static_cast<std::size_t>(v.dims().z);
  for (int z = 0; z < v.dims().z; ++z) {
    std::memcpy(f.bytes().data() + static_cast<std::size_t>(v.dims().z - 1 - z) * slice,
                v.bytes().data() + static_cast<std::size_t>(z) * slice, slice);
  }
  return f;
}

class FlippedMosaicLayout final : public layout::Layout {
 public:
  static layout::LayoutPlan planFor(const Volume& shape, const gpu::DeviceLimits& limits) {
    layout::LayoutPlan plan = layout::MosaicLayout::planFor(shape, limits);
    plan.layout = kName;
    plan.reason = "slices reversed: " + plan.reason;
    return plan;
  }

  FlippedMosaicLayout(const Volume& volume, const gpu::DeviceLimits& limits,
                      gpu::MemoryLedger& ledger)
      : stored_(std::make_unique<Volume>(flippedInZ(volume))),
        mosaic_(layout::MosaicLayout::create(*stored_, limits, ledger)),
        plan_(planFor(volume, limits)) {
    // Value blocks (empty-space skipping) come from the original voxels:
    // sampleVolume() returns their field at the original positions.
    voxels_ = &volume;
  }

  std::string name() const override { return kName; }
  const layout::LayoutPlan& plan() const override { return plan_; }
  gpu::ShaderPart glsl() const override {
    std::string text = kRename;
    for (const gpu::ShaderPart& part : mosaic_->glslParts()) text += part.text + "\n";
    text += kWrapper;
    return {"flipped_mosaic.glsl (mosaic.glsl inside)", text};
  }
  int bind(const gpu::Program& program, int firstUnit) const override {
    return mosaic_->bind(program, firstUnit);
  }
  layout::ValueMapping rawFromStored() const override { return mosaic_->rawFromStored(); }
  int textureUnits() const override { return mosaic_->textureUnits(); }
  glm::ivec3 volumeDims() const override { return mosaic_->volumeDims(); }
  std::uint64_t textureBytes() const override { return mosaic_->textureBytes(); }

  const layout::MosaicLayout& stored() const { return *mosaic_; }

 private:
  std::unique_ptr<Volume> stored_;  // the reversed copy the mosaic was made from
  std::unique_ptr<layout::MosaicLayout> mosaic_;
  layout::LayoutPlan plan_;
};

// By name only (automatic = false): "auto" keeps choosing the built-in
// layouts, so tests of the planner's choice see no change.
const bool kRegistered = [] {
  layout::LayoutRegistry::global().add(
      {.name = kName,
       .automatic = false,
       .plan = [](const Volume& shape, const gpu::DeviceLimits& limits,
                  int) { return FlippedMosaicLayout::planFor(shape, limits); },
       .create = [](const Volume& volume, const gpu::DeviceLimits& limits,
                    gpu::MemoryLedger& ledger, int) -> std::unique_ptr<layout::Layout> {
         return std::make_unique<FlippedMosaicLayout>(volume, limits, ledger);
       }});
  return true;
}();

}  // namespace

TEST(RegistryExtension, TheFlippedMosaicIsRegisteredByNameOnly) {
  ASSERT_TRUE(kRegistered);
  const layout::LayoutEntry& e = layout::LayoutRegistry::global().find(kName);
  EXPECT_FALSE(e.automatic);
  EXPECT_TRUE(e.holdsVoxelGrid);
  EXPECT_FALSE(e.streamsBricks);
  EXPECT_TRUE(e.runsOn(gpu::DeviceLimits::of(test::gpuContext().caps())));
}

// The shared layoutsFor() (tests/support/TestLayouts.h) picks it up, so the
// shading and clipping tests render through it too; on the volume those
// tests use, a layout that can (packed-mosaic) is squeezed across several
// textures, as their own lists did.
TEST(RegistryExtension, SharedLayoutsForIncludesTheFlippedMosaic) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSphere({37, 53, 29});
  const auto layouts = test::layoutsFor(c, v);
  const auto any = [&](auto predicate) {
    return std::any_of(layouts.begin(), layouts.end(), predicate);
  };
  EXPECT_TRUE(any([](const auto& l) { return l->name() == kName; })) << test::layoutNames(layouts);
  EXPECT_TRUE(any([](const auto& l) { return l->textureUnits() >= 2; }))
      << test::layoutNames(layouts);
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  std::size_t expected = 0;
  for (const layout::LayoutEntry& e : layout::LayoutRegistry::global().entries()) {
    expected += e.holdsVoxelGrid && !e.streamsBricks && e.runsOn(limits) ? 1 : 0;
  }
  EXPECT_EQ(layouts.size(), expected) << test::layoutNames(layouts);
}

// Stored reversed, sampled straight: at every voxel centre it returns the
// original voxel (within the probe's precision), and the mosaic under it
// returns the mirrored one, which differs on this asymmetric phantom.
TEST(RegistryExtension, TheFlippedMosaicStoresSlicesReversedAndSamplesTheVoxels) {
  gpu::GlContext& c = test::gpuContext();
  layout::LayoutProbe probe(c);
  if (!probe.hasFloatTargets()) GTEST_SKIP() << "no float render targets to read samples back";
  const Volume v = makeSheppLogan({21, 23, 15});
  const FlippedMosaicLayout l(v, gpu::DeviceLimits::of(c.caps()), c.ledger());
  const std::vector<glm::vec3> positions = layout::LayoutProbe::voxelCentres(v.dims());
  const std::vector<float> got = probe.sample(l, positions);
  const std::vector<float> stored = probe.sample(l.stored(), positions);
  const layout::ValueMapping m = l.rawFromStored();
  double worst = 0.0, mirroredDiffers = 0.0;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const glm::vec3 p = positions[i] * glm::vec3(v.dims()) - 0.5f;
    const int x = static_cast<int>(std::lround(p.x)), y = static_cast<int>(std::lround(p.y)),
              z = static_cast<int>(std::lround(p.z));
    worst = std::max(worst, std::abs(m.scale * got[i] + m.offset - v.valueAt(x, y, z)));
    mirroredDiffers =
        std::max(mirroredDiffers, std::abs(m.scale * stored[i] + m.offset - v.valueAt(x, y, z)));
  }
  const double range = v.valueRange().max - v.valueRange().min;
  EXPECT_LE(worst, 1e-3 * range);
  EXPECT_GT(mirroredDiffers, 0.1 * range) << "the stored copy must be the reversed one";
}
