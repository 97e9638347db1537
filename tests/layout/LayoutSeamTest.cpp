// What every layout offers through the seam besides sampleVolume(): the
// gradient (layout/gradient.glsl, central differences through sampleVolume)
// against its CPU twin Reconstruction::gradient, and the value blocks for
// empty-space skipping, whose min/max must bound every sample in a block.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "support/GpuTestContext.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/LayoutProbe.h"
#include "tessera/layout/MosaicLayout.h"
#include "tessera/layout/PackedMosaicLayout.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/layout/ValueBlocks.h"
#include "tessera/reference/Reconstruction.h"

using namespace tessera;

namespace {

// A smooth u8 field (no flat regions, so every gradient component matters;
// u8 so that every layout stores it exactly, packed-mosaic's RGBA8 too).
Volume smoothField(glm::ivec3 dims) {
  Volume v = Volume::allocate(dims, ScalarType::U8, "smooth field");
  for (int z = 0; z < dims.z; ++z) {
    for (int y = 0; y < dims.y; ++y) {
      for (int x = 0; x < dims.x; ++x) {
        const double s = std::sin(0.35 * x) * std::cos(0.21 * y) + 0.02 * z * z / dims.z;
        v.setValueAtIndex(v.index(x, y, z), 128.0 + 100.0 * s);
      }
    }
  }
  return v;
}

using LayoutMaker = std::function<std::unique_ptr<layout::Layout>(const Volume&, gpu::GlContext&)>;

std::vector<std::pair<std::string, LayoutMaker>> layouts() {
  auto limits = [](gpu::GlContext& c) { return gpu::DeviceLimits::of(c.caps()); };
  return {
      {"texture3d",
       [=](const Volume& v, gpu::GlContext& c) -> std::unique_ptr<layout::Layout> {
         return layout::Texture3DLayout::create(v, limits(c), c.ledger());
       }},
      {"mosaic",
       [=](const Volume& v, gpu::GlContext& c) -> std::unique_ptr<layout::Layout> {
         return layout::MosaicLayout::create(v, limits(c), c.ledger());
       }},
      {"packed-mosaic",
       [=](const Volume& v, gpu::GlContext& c) -> std::unique_ptr<layout::Layout> {
         return layout::PackedMosaicLayout::create(v, limits(c), c.ledger(), 4);
       }},
  };
}

}  // namespace

TEST(LayoutSeam, GradientMatchesTheCpuTwinOnEveryLayout) {
  gpu::GlContext& c = test::gpuContext();
  layout::LayoutProbe probe(c);
  if (!probe.hasFloatTargets()) GTEST_SKIP() << "no float render targets";
  const Volume v = smoothField({20, 18, 16});
  const TrilinearReconstruction field(v);
  // Voxel centres (exact texture weights) and random interior points.
  std::vector<glm::vec3> positions = layout::LayoutProbe::voxelCentres(v.dims());
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.05f, 0.95f);
  for (int i = 0; i < 2000; ++i) positions.emplace_back(u(rng), u(rng), u(rng));
  const double range = v.valueRange().width();
  for (const auto& [name, make] : layouts()) {
    const auto layout = make(v, c);
    const std::vector<glm::vec4> got = probe.sampleGradient(*layout, positions);
    const layout::ValueMapping m = layout->rawFromStored();
    const std::size_t centres = static_cast<std::size_t>(v.voxelCount());
    double worstCentre = 0.0, worstAny = 0.0;
    for (std::size_t i = 0; i < positions.size(); ++i) {
      const glm::dvec3 expected = field.gradient(glm::dvec3(positions[i]));
      const glm::dvec3 gpuRaw = glm::dvec3(got[i]) * m.scale;
      // Error relative to the range per voxel (the scale of a gradient).
      double err = 0.0;
      for (int a = 0; a < 3; ++a) {
        err = std::max(err, std::abs(gpuRaw[a] - expected[a]) / (range * v.dims()[a]));
      }
      (i < centres ? worstCentre : worstAny) = std::max(i < centres ? worstCentre : worstAny, err);
    }
    std::printf(
        "  [measured] %s: gradient error at voxel centres %.2e, anywhere %.2e "
        "(of the range per voxel)\n",
        name.c_str(), worstCentre, worstAny);
    EXPECT_LT(worstCentre, 1e-4) << name;
    // Between centres the GPU filters with 8-bit sub-texel weights (llvmpipe).
    EXPECT_LT(worstAny, 1e-2) << name;
  }
}

TEST(LayoutSeam, ValueBlocksBoundEverySampleInTheirBlock) {
  Volume v = makeSheppLogan({27, 22, 19});
  std::mt19937 rng(3);
  for (const int blockSize : {4, 8}) {
    for (const int support : {1, 2}) {
      const layout::ValueBlocks blocks(v, blockSize, support);
      const TrilinearReconstruction field(v);
      std::uniform_real_distribution<double> u(0.0, 1.0);
      int checked = 0;
      for (int i = 0; i < 20000; ++i) {
        const glm::dvec3 p(u(rng), u(rng), u(rng));
        const glm::ivec3 cell = glm::min(glm::ivec3(p * glm::dvec3(v.dims()) / double(blockSize)),
                                         blocks.blockCount() - 1);
        const std::size_t b = blocks.index(cell.x, cell.y, cell.z);
        const double s = field.value(p);
        EXPECT_GE(s, blocks.mins()[b] - 1e-9);
        EXPECT_LE(s, blocks.maxs()[b] + 1e-9);
        ++checked;
      }
      EXPECT_EQ(checked, 20000);
    }
  }
  // A wider support can only widen a block's range.
  const layout::ValueBlocks narrow(v, 8, 1), wide(v, 8, 2);
  bool widened = false;
  for (std::size_t i = 0; i < narrow.mins().size(); ++i) {
    EXPECT_LE(wide.mins()[i], narrow.mins()[i]);
    EXPECT_GE(wide.maxs()[i], narrow.maxs()[i]);
    widened |= wide.maxs()[i] > narrow.maxs()[i] || wide.mins()[i] < narrow.mins()[i];
  }
  EXPECT_TRUE(widened);
}

TEST(LayoutSeam, ValueBlocksCountMissingVoxelsAsTheyRender) {
  Volume v = Volume::allocate({8, 8, 8}, ScalarType::F32);
  for (std::size_t i = 0; i < v.voxelCount(); ++i) v.setValueAtIndex(i, 10.0 + i % 7);
  v.setValueAtIndex(0, std::nan(""));
  const layout::ValueBlocks blocks(v, 4, 1);
  EXPECT_FLOAT_EQ(blocks.mins()[0], static_cast<float>(v.nonFiniteValue()));
  EXPECT_FALSE(std::isnan(blocks.maxs()[0]));
}

TEST(LayoutSeam, InCoreLayoutsGiveTheValueBlocksOfTheirVolume) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = smoothField({20, 18, 16});
  const layout::ValueBlocks direct(v, 8, 1);
  for (const auto& [name, make] : layouts()) {
    const auto layout = make(v, c);
    EXPECT_EQ(layout->supportVoxels(), 1) << name;
    const layout::ValueBlocks got = layout->valueBlocks(8);
    EXPECT_EQ(got.mins(), direct.mins()) << name;
    EXPECT_EQ(got.maxs(), direct.maxs()) << name;
  }
}
