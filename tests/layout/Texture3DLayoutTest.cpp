// texture3d layout: address maths and value mapping against direct indexing.
#include <gtest/gtest.h>

#include <cmath>

#include "layout/LayoutFixtures.h"
#include "support/GpuTestContext.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/LayoutProbe.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/reference/ReferenceRaycaster.h"

using namespace tessera;

namespace {
gpu::GlContext& context() {
  return test::gpuContext();
}

using test::addressPattern;
}  // namespace

TEST(Texture3DLayout, SampleMatchesDirectIndexForEveryVoxel) {
  gpu::GlContext& c = context();
  for (ScalarType type : {ScalarType::U8, ScalarType::U16, ScalarType::I16, ScalarType::F32}) {
    const Volume v = addressPattern({13, 7, 5}, type);
    auto layout = layout::Texture3DLayout::create(v, gpu::DeviceLimits::of(c.caps()), c.ledger());
    const auto positions = layout::LayoutProbe::voxelCentres(v.dims());
    const std::vector<float> stored = layout::LayoutProbe(c).sample(*layout, positions);
    const layout::ValueMapping m = layout->rawFromStored();
    const ValueRange r = v.valueRange();
    // u8 is stored exactly; 16-bit storage is exact to half a quantum.
    const double tolerance =
        type == ScalarType::U8 ? 1e-3 : 0.51 * r.width() / 65535.0 + 1e-6 * r.width();
    for (std::size_t i = 0; i < positions.size(); ++i) {
      ASSERT_NEAR(m.scale * stored[i] + m.offset, v.valueAtIndex(i), tolerance)
          << "type " << scalarTypeName(type) << " voxel " << i;
    }
  }
}

TEST(Texture3DLayout, InterpolationBetweenVoxelsMatchesReferenceTrilinear) {
  gpu::GlContext& c = context();
  const Volume v = makeSheppLogan({24, 20, 16});
  auto layout = layout::Texture3DLayout::create(v, gpu::DeviceLimits::of(c.caps()), c.ledger());
  std::vector<glm::vec3> positions;
  for (int i = 0; i < 4000; ++i) {
    // A deterministic scatter over the whole box, edges included.
    positions.emplace_back(std::fmod(i * 0.6180339887f, 1.0f), std::fmod(i * 0.7548776662f, 1.0f),
                           std::fmod(i * 0.5698402910f, 1.0f));
  }
  const std::vector<float> stored = layout::LayoutProbe(c).sample(*layout, positions);
  double worst = 0.0;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const double gpu = 255.0 * stored[i];
    const double cpu = sampleTrilinear(v, glm::dvec3(positions[i]));
    worst = std::max(worst, std::abs(gpu - cpu));
  }
  // GPUs interpolate with limited fraction precision (8 bits on llvmpipe,
  // the minimum GL allows): at most one weight quantum (1/256) per axis on a
  // neighbour step of at most 255 — 3 x 255/256 ≈ 3 grey levels — where
  // Shepp–Logan's skull has full-range steps.
  EXPECT_LE(worst, 3.0);
  std::printf("  [measured] worst |GPU - CPU trilinear| = %.3f of 255\n", worst);
}

TEST(Texture3DLayout, PlanReportsBytesAndRefusesOversizedVolumes) {
  gpu::GlContext& c = context();
  const Volume v = makeSphere({40, 30, 20});
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  const layout::LayoutPlan plan = layout::Texture3DLayout::planFor(v, limits);
  EXPECT_TRUE(plan.fits);
  EXPECT_EQ(plan.totalBytes, 40u * 30 * 20);
  ASSERT_EQ(plan.textures.size(), 1u);
  EXPECT_EQ(plan.textures[0].format, "R8");
  auto layout = layout::Texture3DLayout::create(v, gpu::DeviceLimits::of(c.caps()), c.ledger());
  EXPECT_EQ(layout->textureBytes(), plan.totalBytes);

  gpu::DeviceLimits small = limits;
  small.max3DTextureSize = 32;
  EXPECT_FALSE(layout::Texture3DLayout::planFor(v, small).fits);
  EXPECT_NE(layout::Texture3DLayout::planFor(v, small).reason.find("exceeds"), std::string::npos);
  EXPECT_THROW(layout::Texture3DLayout::create(v, small, c.ledger()), GpuError);
  gpu::DeviceLimits tight = limits;
  tight.textureBudget = 40 * 30 * 20 - 1;
  EXPECT_FALSE(layout::Texture3DLayout::planFor(v, tight).fits);
  gpu::DeviceLimits es2 = limits;
  es2.api = gpu::ApiLevel::Gles2;
  es2.max3DTextureSize = 0;
  EXPECT_FALSE(layout::Texture3DLayout::planFor(v, es2).fits);
}
