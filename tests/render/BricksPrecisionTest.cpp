// Bricks keep the data's precision: u16 and i16 values are stored exactly in
// 16 bits (R16, or two bytes in RG8 / LUMINANCE_ALPHA recombined by the
// shader), f32 in 16 bits over its value range, and the window is applied
// as for in-core layouts. Checked at every voxel centre through each texel
// format against direct indexing, and as images under windows of 1 %, 10 %
// and 100 % of the value range against texture3d (ES 3) and the CPU
// reference (ES 3 and ES 2).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "support/BricksTestSupport.h"
#include "support/EachApi.h"
#include "support/GpuTestContext.h"
#include "support/TestCameras.h"
#include "support/TestTransferFunctions.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/BricksLayout.h"
#include "tessera/layout/LayoutProbe.h"
#include "tessera/layout/MosaicLayout.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/lod/BrickGrid.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/Raycaster.h"

using namespace tessera;

namespace {

constexpr int kImage = 96;

// Shepp-Logan (u8 0..255) mapped to `type` over [lo, hi], plus a ramp along
// x so that neighbouring voxels differ by less than one 8-bit step of the
// range: what 8-bit bricks lost.
std::shared_ptr<Volume> phantom(ScalarType type, double lo, double hi, glm::ivec3 dims) {
  const Volume u8 = makeSheppLogan(dims);
  auto v = std::make_shared<Volume>(Volume::allocate(dims, type));
  v->setSpacing(u8.spacing());
  for (int z = 0; z < dims.z; ++z)
    for (int y = 0; y < dims.y; ++y)
      for (int x = 0; x < dims.x; ++x) {
        const std::size_t i = v->index(x, y, z);
        const double t = (u8.valueAtIndex(i) + 0.9 * x / dims.x) / 256.0;
        double value = lo + t * (hi - lo);
        if (type != ScalarType::F32) value = std::round(value);
        v->setValueAtIndex(i, value);
      }
  v->invalidateRange();
  return v;
}

using test::levelZeroBricks;

void refine(layout::BricksLayout& bricks, const Camera& cam, const TransferFunction& tf) {
  test::refineBricks(bricks, cam, tf, kImage);
}

// Every voxel centre through sampleVolume() equals the voxel's raw value
// (rawFromStored applied): exact storage, no 8-bit rounding.
void expectExactAtVoxelCentres(gpu::GlContext& c, const gpu::DeviceLimits& limits,
                               const std::shared_ptr<Volume>& v, const std::string& format) {
  auto bricks = layout::BricksLayout::create(std::make_shared<lod::InCoreMultiresSource>(v, 8),
                                             limits, c.ledger(), levelZeroBricks(12));
  EXPECT_NE(bricks->plan().reason.find(format), std::string::npos) << bricks->plan().reason;
  refine(*bricks, test::orbitCamera(v->extent(), 30, 20), test::visibleTf());
  layout::LayoutProbe probe(c);
  const std::vector<glm::vec3> centres = layout::LayoutProbe::voxelCentres(v->dims());
  const std::vector<float> got = probe.sample(*bricks, centres);
  ASSERT_EQ(got.size(), centres.size());
  const layout::ValueMapping m = bricks->rawFromStored();
  double worst = 0.0;
  for (std::size_t k = 0; k < got.size(); ++k) {
    const double raw = m.scale * got[k] + m.offset;
    worst = std::max(worst, std::abs(raw - v->valueAtIndex(k)));
  }
  // Far below one 8-bit step of the range (what 8-bit bricks lost: up to
  // half of range / 255): the sampler's coordinate rounding mixes in about
  // 1e-4 of a neighbour at a voxel centre, on every 16-bit format and on
  // texture3d alike.
  const ValueRange r = v->valueRange();
  const double tolerance = 2e-4 * (r.max - r.min);
  EXPECT_LE(worst, tolerance) << format << " " << scalarTypeName(v->type());
  std::printf(
      "  [measured] %s %s: worst |sampleVolume - voxel| %.4g = %.2g of the range (an "
      "8-bit step: %.2g)\n",
      format.c_str(), std::string(scalarTypeName(v->type())).c_str(), worst,
      worst / (r.max - r.min), 1.0 / 255.0);
}

}  // namespace

TEST(BricksPrecision, StoredMappingIsExactForSixteenBitIntegers) {
  Volume i16 = Volume::allocate({4, 1, 1}, ScalarType::I16);
  const double values[] = {-32768.0, -1.0, 0.0, 32767.0};
  for (int i = 0; i < 4; ++i) i16.setValueAtIndex(static_cast<std::size_t>(i), values[i]);
  i16.invalidateRange();
  const lod::StoredMapping m = lod::StoredMapping::of(i16);
  EXPECT_EQ(m.bits, 16);
  EXPECT_TRUE(m.exact);
  for (double v : values) EXPECT_EQ(m.raw(m.store(v)), v);
  const lod::StoredMapping u16 =
      lod::StoredMapping::of(Volume::allocate({1, 1, 1}, ScalarType::U16));
  EXPECT_EQ(u16.store(65535.0), 65535);
  EXPECT_EQ(u16.raw(40000.0), 40000.0);
  // f32: 16 bits over the value range, whatever the window.
  Volume f = Volume::allocate({2, 1, 1}, ScalarType::F32);
  f.setValueAtIndex(0, -3.0);
  f.setValueAtIndex(1, 5.0);
  f.invalidateRange();
  f.setWindow({0.0, 0.01});
  const lod::StoredMapping mf = lod::StoredMapping::of(f);
  EXPECT_FALSE(mf.exact);
  EXPECT_EQ(mf.store(-3.0), 0);
  EXPECT_EQ(mf.store(5.0), 65535);
  EXPECT_NEAR(mf.raw(mf.store(0.005)), 0.005, 8.0 / 65535.0);
  EXPECT_EQ(mf.store(std::nan("")), 0);
}

TEST(BricksPrecision, EveryVoxelCentreIsExactThroughEachTexelFormat) {
  const auto i16 = phantom(ScalarType::I16, -1024.0, 3071.0, {37, 29, 23});
  const auto u16 = phantom(ScalarType::U16, 0.0, 65535.0, {37, 29, 23});
  const auto f32 = phantom(ScalarType::F32, -0.5, 2.5, {37, 29, 23});
  {
    test::ApiContext context(gpu::ApiLevel::Gles3);
    gpu::GlContext& c = context.get();
    gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
    if (limits.norm16Textures) {
      for (const auto& v : {i16, u16, f32}) expectExactAtVoxelCentres(c, limits, v, "R16");
    } else {
      std::printf("  [note] this context has no EXT_texture_norm16: R16 not checked\n");
    }
    limits.norm16Textures = false;  // as on a GPU without it
    for (const auto& v : {i16, u16, f32}) expectExactAtVoxelCentres(c, limits, v, "RG8");
  }
  test::ApiContext context(gpu::ApiLevel::Gles2);
  gpu::GlContext& c = context.get();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  for (const auto& v : {i16, u16, f32}) expectExactAtVoxelCentres(c, limits, v, "LA8");
}

using BricksPrecisionOnEachApi = test::EachApi;
INSTANTIATE_TEST_SUITE_P(Api, BricksPrecisionOnEachApi, test::kEveryApi, test::apiParamName);

// A CT-like i16 volume, a u16 and an f32 one, each under windows of 1 %,
// 10 % and 100 % of the range: bricks give the in-core image (ES 3) and the
// reference's (both APIs). With 8-bit bricks the 1 % window had about two
// grey levels left.
TEST_P(BricksPrecisionOnEachApi, NarrowWindowsGiveTheInCoreImage) {
  gpu::GlContext& c = context();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  const bool es3 = GetParam() == gpu::ApiLevel::Gles3;
  struct Case {
    ScalarType type;
    double lo, hi;
  };
  const TransferFunction tf = test::visibleTf();
  for (const Case& k : {Case{ScalarType::I16, -1024.0, 3071.0}, Case{ScalarType::U16, 0.0, 60000.0},
                        Case{ScalarType::F32, -0.5, 2.5}}) {
    for (const double fraction : {0.01, 0.1, 1.0}) {
      auto v = phantom(k.type, k.lo, k.hi, {48, 40, 36});
      // Centred on the phantom's brain tissue (u8 ~ 100 of 255).
      const double width = fraction * (k.hi - k.lo);
      const double centre = fraction < 1.0 ? k.lo + 0.4 * (k.hi - k.lo) : 0.5 * (k.lo + k.hi);
      v->setWindow({centre - width / 2, centre + width / 2});
      auto bricks = layout::BricksLayout::create(std::make_shared<lod::InCoreMultiresSource>(v, 8),
                                                 limits, c.ledger(), levelZeroBricks(12));
      const Camera cam = test::orbitCamera(v->extent(), 35, 25);
      refine(*bricks, cam, tf);
      auto draw = [&](const layout::Layout& layout) {
        render::Raycaster caster(c, *v, layout);
        caster.setTransferFunction(tf);
        return caster.render(cam, RenderSettings(), kImage, kImage);
      };
      const Image viaBricks = draw(*bricks);
      const Image ref = renderReference(*v, tf, cam, RenderSettings(), kImage, kImage);
      const double vsRef = psnr(viaBricks, ref);
      const std::string what = std::string(scalarTypeName(k.type)) + " window " +
                               std::to_string(static_cast<int>(100.0 * fraction));
      if (es3) {
        const auto inCore = layout::Texture3DLayout::create(*v, limits, c.ledger());
        const Image viaInCore = draw(*inCore);
        const double vsInCore = psnr(viaBricks, viaInCore);
        EXPECT_GE(vsInCore, 55.0) << what;
        EXPECT_GE(vsRef, 60.0) << what;
        // Without EXT_texture_norm16: two bytes in RG8, interpolated by hand.
        gpu::DeviceLimits noNorm16 = limits;
        noNorm16.norm16Textures = false;
        auto rg8 = layout::BricksLayout::create(std::make_shared<lod::InCoreMultiresSource>(v, 8),
                                                noNorm16, c.ledger(), levelZeroBricks(12));
        refine(*rg8, cam, tf);
        const double rg8VsInCore = psnr(draw(*rg8), viaInCore);
        EXPECT_GE(rg8VsInCore, 55.0) << what << " RG8";
        std::printf(
            "  [measured] ES3 %s%%: bricks vs texture3d %.2f dB (RG8 atlas %.2f dB), vs "
            "reference %.2f dB\n",
            what.c_str(), vsInCore, rg8VsInCore, vsRef);
      } else {
        // ES 2 has no 16-bit texture: the in-core mosaic keeps 8 bits, the
        // bricks two bytes (LUMINANCE_ALPHA).
        const auto mosaic = layout::MosaicLayout::create(*v, limits, c.ledger());
        const double mosaicVsRef = psnr(draw(*mosaic), ref);
        EXPECT_GE(vsRef, 60.0) << what;
        EXPECT_GE(vsRef, mosaicVsRef) << what;
        std::printf("  [measured] ES2 %s%%: bricks vs reference %.2f dB (8-bit mosaic %.2f dB)\n",
                    what.c_str(), vsRef, mosaicVsRef);
      }
    }
  }
}
