// lod::ZarrMultiresSource: an OME-Zarr store as the pyramid the bricked
// layout reads. Its levels are lod::downsample's (the writer's filter), its
// boxes equal the same voxels of the whole level, and concurrent readBox
// calls (the streaming scheduler's workers) agree with serial ones.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <thread>

#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/ZarrWriter.h"
#include "tessera/lod/Downsample.h"
#include "tessera/lod/ZarrMultiresSource.h"

namespace tessera::lod {
namespace {

Volume ramp(glm::ivec3 d) {
  Volume v = Volume::allocate(d, ScalarType::U16, "ramp");
  std::mt19937 rng(5);
  for (std::size_t i = 0; i < v.voxelCount(); ++i) v.setValueAtIndex(i, double(rng() % 4000));
  v.setSpacing({0.8, 0.9, 1.5});
  v.setOrigin({5.0, -7.0, 2.0});
  v.invalidateRange();
  return v;
}

bool boxEquals(const Volume& box, const Volume& whole, glm::ivec3 lo) {
  for (int z = 0; z < box.dims().z; ++z) {
    for (int y = 0; y < box.dims().y; ++y) {
      if (std::memcmp(box.bytes().data() + box.index(0, y, z) * 2,
                      whole.bytes().data() + whole.index(lo.x, lo.y + y, lo.z + z) * 2,
                      std::size_t(box.dims().x) * 2) != 0) {
        return false;
      }
    }
  }
  return true;
}

TEST(ZarrMultiresSource, LevelsAreTheDownsamplePyramidAndBoxesMatchTheLevel) {
  const test::TempDir tmp;
  const Volume v = ramp({61, 47, 35});
  OmeZarrWriteOptions o;
  o.chunk = 16;
  writeOmeZarr(v, tmp / "r.ome.zarr", o);
  const auto source = ZarrMultiresSource::open((tmp / "r.ome.zarr").string());
  ASSERT_EQ(source->levelCount(), 3);  // 61x47x35, 31x24x18, 16x12x9
  EXPECT_EQ(source->shape().dims(), v.dims());
  EXPECT_FALSE(source->shape().hasData());
  EXPECT_EQ(source->shape().window().min, v.valueRange().min);
  Volume expect = v;
  for (int l = 0; l < source->levelCount(); ++l) {
    SCOPED_TRACE(l);
    if (l > 0) expect = downsample(expect, glm::ivec3(2));
    const LevelInfo info = source->levelInfo(l);
    ASSERT_EQ(info.dims, expect.dims());
    EXPECT_FLOAT_EQ(info.spacing.x, float(expect.spacing().x));
    EXPECT_EQ(info.chunk, glm::min(glm::ivec3(16), info.dims));
    const Volume level = source->readBox(l, {glm::ivec3(0), info.dims});
    ASSERT_TRUE(boxEquals(level, expect, glm::ivec3(0)));
    // The store's geometry is the downsampled volume's.
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(level.origin()[a], expect.origin()[a], 1e-9);
  }
}

TEST(ZarrMultiresSource, ConcurrentBoxesEqualTheLevel) {
  const test::TempDir tmp;
  const Volume v = ramp({70, 50, 40});
  OmeZarrWriteOptions o;
  o.chunk = 16;
  o.compressor = ZarrCompressor::Blosc;
  writeOmeZarr(v, tmp / "c.ome.zarr", o);
  const auto source = ZarrMultiresSource::open((tmp / "c.ome.zarr").string());
  std::atomic<int> bad{0};
  std::vector<std::thread> workers;
  for (int t = 0; t < 4; ++t) {
    workers.emplace_back([&, t] {
      std::mt19937 rng{static_cast<unsigned>(t)};
      for (int i = 0; i < 25; ++i) {
        glm::ivec3 lo, hi;
        for (int a = 0; a < 3; ++a) {
          lo[a] = int(rng() % unsigned(v.dims()[a] - 1));
          hi[a] = lo[a] + 1 + int(rng() % unsigned(v.dims()[a] - lo[a]));
        }
        const Volume box = source->readBox(0, {lo, hi});
        if (box.dims() != hi - lo || !boxEquals(box, v, lo)) ++bad;
        const glm::dvec3 want = v.worldOf(glm::dvec3(lo));
        if (glm::length(box.origin() - want) > 1e-9) ++bad;
      }
    });
  }
  for (auto& w : workers) w.join();
  EXPECT_EQ(bad, 0);
  EXPECT_THROW(source->readBox(0, {glm::ivec3(0), glm::ivec3(71, 50, 40)}), InputError);
  EXPECT_THROW(source->readBox(4, {glm::ivec3(0), glm::ivec3(1)}), InputError);
}

}  // namespace
}  // namespace tessera::lod
