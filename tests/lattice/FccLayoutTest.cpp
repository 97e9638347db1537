// The FCC lattice on the GPU: the layout's GLSL box spline against the CPU
// evaluator (LayoutProbe), its renders against the CPU reference's FCC
// render, its value blocks, and what the planner says about it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <utility>

#include "lattice/Blobs.h"
#include "support/GpuTestContext.h"
#include "support/TestCameras.h"
#include "support/TestTransferFunctions.h"
#include "tessera/core/Error.h"
#include "tessera/io/Procedural.h"
#include "tessera/lattice/BoxSplineReconstruction.h"
#include "tessera/lattice/FccBoxSpline.h"
#include "tessera/lattice/FccResampling.h"
#include "tessera/lattice/MarschnerLobb.h"
#include "tessera/layout/FccLayout.h"
#include "tessera/layout/LayoutProbe.h"
#include "tessera/layout/Planner.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/Raycaster.h"

using namespace tessera;
using namespace tessera::lattice;

namespace {

gpu::DeviceLimits nativeLimits() {
  return gpu::DeviceLimits::of(test::gpuContext().caps());
}

// A lattice of an odd grid whose coefficients are random in [-0.25, 1.25]
// (quasi-interpolated data overshoot the window): every address and weight
// shows in the values.
FccVolume randomLattice(glm::ivec3 grid, ScalarType type, unsigned seed) {
  Volume box = Volume::shapeOnly(grid, type);
  box.setWindow({0.0, type == ScalarType::U8 ? 255.0 : 1.0});
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> d(type == ScalarType::U8 ? 0.0f : -0.25f,
                                          type == ScalarType::U8 ? 255.0f : 1.25f);
  const glm::ivec3 packed = FccVolume::packedDims(grid);
  std::vector<float> texels(static_cast<std::size_t>(packed.x) * packed.y * packed.z);
  for (float& t : texels) t = type == ScalarType::U8 ? std::round(d(rng)) : d(rng);
  return FccVolume::fromTexels(box, grid, type, texels);
}

// Positions in [0,1]^3 (a margin of half a grid unit outside the lattice's
// centres included: the boundary rule) and every lattice point's centre.
std::vector<glm::vec3> probePositions(const FccVolume& fcc, int randomCount) {
  std::vector<glm::vec3> out;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> d(0.0f, 1.0f);
  for (int i = 0; i < randomCount; ++i) out.emplace_back(d(rng), d(rng), d(rng));
  const glm::ivec3 g = fcc.gridDims();
  for (int z = 0; z < g.z; ++z)
    for (int y = 0; y < g.y; ++y)
      for (int x = 0; x < g.x; ++x)
        if (FccVolume::isLatticePoint({x, y, z})) {
          out.emplace_back((glm::vec3(x, y, z) + 0.5f) / glm::vec3(g));
        }
  return out;
}

struct ProbeError {
  double max = 0.0;
  std::size_t count = 0;
};

ProbeError probeAgainstCpu(const FccVolume& fcc, layout::FccLayout::Storage storage) {
  const auto layout =
      layout::FccLayout::create(fcc, nativeLimits(), test::gpuContext().ledger(), "fcc", storage);
  EXPECT_EQ(layout->storage(), storage);
  layout::LayoutProbe probe(test::gpuContext());
  const std::vector<glm::vec3> at = probePositions(fcc, 8000);
  const std::vector<float> gpuValues = probe.sample(*layout, at);
  const FccBoxSpline spline(fcc);
  const double scale = layout->rawFromStored().scale;
  ProbeError e;
  e.count = at.size();
  for (std::size_t i = 0; i < at.size(); ++i) {
    // The CPU evaluator at the float position the GPU got.
    const glm::dvec3 u = glm::dvec3(at[i]) * glm::dvec3(fcc.gridDims()) - 0.5;
    e.max = std::max(e.max, std::abs(gpuValues[i] * scale - spline.value(u)) / scale);
  }
  return e;
}

std::unique_ptr<render::Raycaster> makeCaster(const Volume& box, const layout::Layout& layout,
                                              int skipBlock) {
  auto caster = std::make_unique<render::Raycaster>(test::gpuContext(), box, layout);
  caster->setSkipBlockSize(skipBlock);
  return caster;
}

Camera obliqueCamera(const Volume& v) {
  return test::orbitCamera(v, 30, 20);
}

// The blobs as u8 (255 at 1): a small real-looking volume.
Volume blobs(glm::ivec3 dims) {
  return test::blobs(dims, ScalarType::U8);
}

}  // namespace

// The GLSL pieces (generated BB form), region classification and both
// storages' addressing (packed: 16 fetches; cubes: 5 RGBA fetches, channels
// reordered by the reflection) against the CPU evaluator, at 8000 random
// points and every lattice point of odd grids, f32 and u8 texels.
TEST(FccLayout, GlslBoxSplineMatchesTheCpuEvaluator) {
  if (!layout::LayoutProbe(test::gpuContext()).hasFloatTargets())
    GTEST_SKIP() << "no float targets";
  using Storage = layout::FccLayout::Storage;
  for (const glm::ivec3 grid : {glm::ivec3(13, 11, 9), glm::ivec3(8, 15, 7)}) {
    for (const Storage storage : {Storage::Packed, Storage::Cubes}) {
      const ProbeError f = probeAgainstCpu(randomLattice(grid, ScalarType::F32, 3), storage);
      const ProbeError b = probeAgainstCpu(randomLattice(grid, ScalarType::U8, 4), storage);
      std::printf(
          "[measured] GLSL vs CPU box spline, grid %dx%dx%d, %s: f32 max %.2e, u8 max "
          "%.2e (of the value scale) over %zu points\n",
          grid.x, grid.y, grid.z, layout::FccLayout::storageName(storage), f.max, b.max, f.count);
      EXPECT_LT(f.max, 2e-5);
      EXPECT_LT(b.max, 2e-5);
    }
  }
}

TEST(FccLayout, RendersLikeTheCpuReferencesFccRender) {
  const RenderSettings settings;
  struct Case {
    std::string name;
    FccVolume fcc;
  };
  const Volume blob = blobs({24, 22, 20});
  const Volume ml = makeMarschnerLobb(glm::ivec3(41));
  std::vector<Case> cases;
  for (const FccDensity density : {FccDensity::Same, FccDensity::Half}) {
    FccResampleOptions o;
    o.density = density;
    cases.push_back(
        {"blobs 24x22x20 u8, " + std::string(fccDensityName(density)), resampleToFcc(blob, o)});
    cases.push_back({"Marschner-Lobb 41^3 f32, " + std::string(fccDensityName(density)),
                     makeMarschnerLobbFcc(ml, density)});
  }
  for (const Case& c : cases) {
    const auto layout =
        layout::FccLayout::create(c.fcc, nativeLimits(), test::gpuContext().ledger());
    const Volume& box = c.fcc.box();
    const Camera cam = obliqueCamera(box);
    auto caster = makeCaster(box, *layout, 8);
    for (const auto& [tfName, tf] :
         {std::pair{"soft", test::visibleTf()}, std::pair{"iso", lattice::marschnerLobbIsoTf()}}) {
      caster->setTransferFunction(tf);
      const Image gpuImage = caster->render(cam, settings, 96, 96);
      const Image ref =
          renderReference(box, BoxSplineReconstruction(c.fcc), tf, cam, settings, 96, 96);
      const double db = psnr(gpuImage, ref);
      std::printf("[measured] %s, %s TF: GPU box spline vs CPU reference %.1f dB, SSIM %.5f\n",
                  c.name.c_str(), tfName, db, ssim(gpuImage, ref));
      EXPECT_GE(db, 40.0) << c.name << " " << tfName;
    }
  }
}

// The comparison has teeth: the GPU render of the same signal without the
// quasi-interpolation step (raw samples as coefficients), or the Cartesian
// trilinear reference, score below 40 dB against the box-spline reference.
TEST(FccLayout, TheComparisonSeesTheReconstruction) {
  const Volume ml = makeMarschnerLobb(glm::ivec3(41));
  const FccVolume fcc = makeMarschnerLobbFcc(ml, FccDensity::Same);
  const FccVolume raw = makeMarschnerLobbFcc(ml, FccDensity::Same, false);
  const TransferFunction tf = lattice::marschnerLobbIsoTf();
  const Camera cam = obliqueCamera(ml);
  const Image ref = renderReference(fcc.box(), BoxSplineReconstruction(fcc), tf, cam, {}, 96, 96);
  auto render = [&](const FccVolume& lattice) {
    const auto layout =
        layout::FccLayout::create(lattice, nativeLimits(), test::gpuContext().ledger());
    auto caster = makeCaster(lattice.box(), *layout, 0);
    caster->setTransferFunction(tf);
    return caster->render(cam, {}, 96, 96);
  };
  const double good = psnr(render(fcc), ref);
  const double unfiltered = psnr(render(raw), ref);
  const double trilinear = psnr(renderReference(ml, tf, cam, {}, 96, 96), ref);
  std::printf(
      "[measured] ML 41^3 FCC same vs the box-spline reference: GPU %.1f dB, GPU without "
      "quasi-interpolation %.1f dB, Cartesian trilinear reference %.1f dB\n",
      good, unfiltered, trilinear);
  EXPECT_GE(good, 40.0);
  EXPECT_LT(unfiltered, 40.0);
  EXPECT_LT(trilinear, 40.0);
}

// Skipping with the layout's value blocks takes the same samples: the image
// does not change, and the blocks bound every value the spline returns.
TEST(FccLayout, ValueBlocksBoundTheSplineAndSkippingKeepsTheImage) {
  const Volume source = blobs({30, 26, 22});
  const FccVolume fcc = resampleToFcc(source);
  const auto layout = layout::FccLayout::create(fcc, nativeLimits(), test::gpuContext().ledger());
  for (const int block : {4, 8}) {
    const layout::ValueBlocks blocks = layout->valueBlocks(block);
    EXPECT_EQ(blocks.blockCount(), (source.dims() + block - 1) / block);
    const FccBoxSpline spline(fcc);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> d(0.0, 1.0);
    for (int i = 0; i < 20000; ++i) {
      const glm::dvec3 p(d(rng), d(rng), d(rng));
      const glm::ivec3 cell = glm::min(
          glm::ivec3(glm::floor(p * glm::dvec3(source.dims()) / static_cast<double>(block))),
          blocks.blockCount() - 1);
      const std::size_t b = blocks.index(cell.x, cell.y, cell.z);
      const double v = spline.value(p * glm::dvec3(fcc.gridDims()) - 0.5);
      ASSERT_GE(v, blocks.mins()[b] - 1e-3) << block;
      ASSERT_LE(v, blocks.maxs()[b] + 1e-3) << block;
    }
  }
  TransferFunction tf;  // only the upper values are visible: most blocks are empty
  tf.addColor(0.0, {1.0, 0.9, 0.7});
  tf.addColor(1.0, {1.0, 0.9, 0.7});
  tf.addOpacity(0.0, 0.0);
  tf.addOpacity(0.55, 0.0);
  tf.addOpacity(1.0, 0.6);
  const Camera cam = obliqueCamera(source);
  auto plain = makeCaster(fcc.box(), *layout, 0);
  auto skipping = makeCaster(fcc.box(), *layout, 4);
  plain->setTransferFunction(tf);
  skipping->setTransferFunction(tf);
  const Image a = plain->render(cam, {}, 80, 80);
  const Image b = skipping->render(cam, {}, 80, 80);
  EXPECT_LT(skipping->occupiedBlockFraction(), 0.8);
  EXPECT_TRUE(std::isinf(psnr(a, b))) << psnr(a, b);
}

// Planner: by name only, its bytes against the profile, refused on gles2.
TEST(FccLayout, PlannerAccountsItsBytesAndRefusesDevicesWithoutEs3) {
  gpu::DeviceCaps caps;
  caps.api = gpu::ApiLevel::Gles3;
  caps.max2DTextureSize = 16384;
  caps.max3DTextureSize = 2048;
  caps.maxTextureUnits = 32;
  caps.maxRenderbufferSize = 16384;
  const gpu::DeviceLimits gles3 = gpu::effectiveLimits(gpu::DeviceProfile::find("gles3"), caps);
  const Volume shape = Volume::shapeOnly({64, 64, 64}, ScalarType::U8);
  layout::PlanRequest r;
  EXPECT_NE(layout::planLayout(shape, gles3, r).layout.layout, "fcc");  // auto never picks it
  r.layout = "fcc";
  // Cube storage where it fits: an RGBA texel per unit cube of the grid
  // (origins -2 .. D), else the x-packed lattice (one texel per point).
  const glm::ivec3 grid = fccGridDims({64, 64, 64}, FccDensity::Same);
  const glm::ivec3 packed = FccVolume::packedDims(grid);
  const std::uint64_t packedBytes = static_cast<std::uint64_t>(packed.x) * packed.y * packed.z;
  const std::uint64_t cubeBytes =
      static_cast<std::uint64_t>(grid.x + 3) * (grid.y + 3) * (grid.z + 3) * 4;  // RGBA8
  const layout::Plan same = layout::planLayout(shape, gles3, r);
  EXPECT_TRUE(same.layout.fits);
  EXPECT_EQ(same.layout.totalBytes, cubeBytes);
  EXPECT_EQ(layout::FccLayout::planFor(grid, ScalarType::U8, gles3, "fcc",
                                       layout::FccLayout::Storage::Packed)
                .totalBytes,
            packedBytes);  // R8
  r.layout = "fcc-half";
  const layout::Plan half =
      layout::planLayout(Volume::shapeOnly({64, 64, 64}, ScalarType::F32), gles3, r);
  EXPECT_EQ(half.layout.totalBytes, 67ull * 67 * 67 * 16);  // RGBA32F cubes of the 64^3 grid
  // A budget the cubes exceed: the packed lattice, and the plan says why.
  gpu::DeviceLimits tight = gles3;
  tight.textureBudget = cubeBytes / 2;
  r.layout = "fcc";
  const layout::Plan fallback = layout::planLayout(shape, tight, r);
  EXPECT_FALSE(fallback.downsampled());
  EXPECT_EQ(fallback.layout.totalBytes, packedBytes);
  EXPECT_NE(fallback.reason.find("not cubes"), std::string::npos) << fallback.reason;
  // Over the budget even packed: the planner halves the volume first, and says so.
  gpu::DeviceLimits small = gles3;
  small.textureBudget = 200 * 1024;
  const layout::Plan reduced = layout::planLayout(shape, small, r);
  EXPECT_TRUE(reduced.downsampled());
  EXPECT_LE(reduced.layout.totalBytes, small.textureBudget);

  caps.api = gpu::ApiLevel::Gles2;
  caps.max3DTextureSize = 0;
  const gpu::DeviceLimits gles2 = gpu::effectiveLimits(gpu::DeviceProfile::find("gles2"), caps);
  try {
    layout::planLayout(shape, gles2, r);
    ADD_FAILURE() << "fcc planned on gles2";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("3D textures"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("gles2"), std::string::npos) << e.what();
    // No Cartesian layout is offered in its place: that would change the
    // reconstruction the user asked for.
    EXPECT_EQ(std::string(e.what()).find("mosaic"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no layout of this kind"), std::string::npos) << e.what();
  }
  const layout::LayoutPlan direct =
      layout::FccLayout::planFor({64, 64, 64}, ScalarType::U8, gles2, "fcc");
  EXPECT_FALSE(direct.fits);
  EXPECT_NE(direct.reason.find("texelFetch"), std::string::npos) << direct.reason;
}

// The GLSL pieces are generated from the exact tables the CPU evaluator
// uses; a change of either without rerunning the generator fails here.
TEST(FccLayout, GeneratedGlslIsUpToDateWithTheExactTables) {
  const std::filesystem::path root =
      std::filesystem::path(TESSERA_TEST_DATA_DIR).parent_path().parent_path();
  if (std::system("python3 --version > /dev/null 2>&1") != 0) GTEST_SKIP() << "no python3";
  const std::string cmd =
      "python3 " + (root / "src/layout/generate_fcc_glsl.py").string() + " --check";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
}
