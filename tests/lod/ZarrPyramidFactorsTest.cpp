// `tessera convert --pyramid-factors 1,2,2` (OmeZarrWriteOptions::factors):
// a pyramid that keeps z, as microscopy stores do, on Zarr v2, v3 and v3
// sharded. Each level's NGFF scale and translation exactly (the half-voxel
// shift of a coarser level in the array's own axes, none on the kept
// axis), each level's voxels equal to a mean computed here, and the store
// read back: dims, spacing, voxel origins in the world (through an LPS
// direction) and the level factors the bricks layout draws it with.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/ZarrStorage.h"
#include "tessera/io/ZarrWriter.h"
#include "tessera/lod/LevelScale.h"
#include "tessera/lod/ZarrMultiresSource.h"

using namespace tessera;

namespace {

namespace fs = std::filesystem;

constexpr glm::ivec3 kKeepZ{2, 2, 1};  // (1, 2, 2) in z, y, x order

// Integer values in f32, dims divisible by 4 along x and y: every mean of
// a 2x2 or 4x4 block of them is exact in f32, so each level equals the mean
// of its block of level 0, computed directly.
Volume ramp(glm::ivec3 d, ScalarType type) {
  Volume v = Volume::allocate(d, type, "ramp");
  for (int z = 0; z < d.z; ++z)
    for (int y = 0; y < d.y; ++y)
      for (int x = 0; x < d.x; ++x) {
        v.setValueAtIndex(v.index(x, y, z), double((x * 7 + y * 13 + z * 101 + x * y) % 997));
      }
  v.invalidateRange();
  v.setSpacing({0.4, 0.5, 2.0});
  v.setOrigin({-3.0, 5.0, 7.0});
  v.setDirection(glm::dmat3(glm::dvec3(-1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, 1)));
  return v;
}

// The mean of level 0's voxels in [s i, s (i + 1)) (clipped to the volume).
double blockMean(const Volume& v, glm::ivec3 i, glm::ivec3 s) {
  double sum = 0.0;
  int n = 0;
  const glm::ivec3 d = v.dims();
  for (int z = s.z * i.z; z < std::min(d.z, s.z * (i.z + 1)); ++z)
    for (int y = s.y * i.y; y < std::min(d.y, s.y * (i.y + 1)); ++y)
      for (int x = s.x * i.x; x < std::min(d.x, s.x * (i.x + 1)); ++x) {
        sum += v.valueAt(x, y, z);
        ++n;
      }
  return sum / n;
}

// The 2x2x1 mean of `v` (partial blocks at odd edges: the voxels present),
// stored in v's type (integers rounded as the writer rounds them).
Volume meanKeepingZ(const Volume& v) {
  const glm::ivec3 o = (v.dims() + kKeepZ - 1) / kKeepZ;
  Volume out = Volume::allocate(o, v.type(), "expected level");
  for (int z = 0; z < o.z; ++z)
    for (int y = 0; y < o.y; ++y)
      for (int x = 0; x < o.x; ++x) {
        out.setValueAtIndex(out.index(x, y, z), blockMean(v, {x, y, z}, kKeepZ));
      }
  return out;
}

nlohmann::json multiscales(const fs::path& store, int format) {
  if (format == 3) {
    return nlohmann::json::parse(
        std::ifstream(store / "zarr.json"))["attributes"]["ome"]["multiscales"][0];
  }
  return nlohmann::json::parse(std::ifstream(store / ".zattrs"))["multiscales"][0];
}

struct Variant {
  const char* name;
  int format;
  int shard;
};

class ZarrPyramidFactors : public ::testing::TestWithParam<Variant> {};

INSTANTIATE_TEST_SUITE_P(Formats, ZarrPyramidFactors,
                         ::testing::Values(Variant{"v2", 2, 0}, Variant{"v3", 3, 0},
                                           Variant{"v3_sharded", 3, 2}),
                         [](const auto& p) { return std::string(p.param.name); });

OmeZarrWriteOptions keepZ(const Variant& variant) {
  OmeZarrWriteOptions o;
  o.chunk = 8;
  o.factors = kKeepZ;
  o.zarrFormat = variant.format;
  o.shard = variant.shard;
  return o;
}

}  // namespace

TEST_P(ZarrPyramidFactors, LevelsKeepZWithExactScalesTranslationsAndMeans) {
  const test::TempDir tmp;
  const fs::path path = tmp / "keeps-z.ome.zarr";
  // 32x24x20 in 8^3 chunks: x and y halve until they fit one chunk (32x24,
  // 16x12, 8x6), z keeps its 20 slices (more than a chunk) on every level.
  const Volume v = ramp({32, 24, 20}, ScalarType::F32);
  const OmeZarrWriteResult r = writeOmeZarr(v, path, keepZ(GetParam()));
  ASSERT_EQ(r.levelDims, (std::vector<glm::ivec3>{{32, 24, 20}, {16, 12, 20}, {8, 6, 20}}));

  const nlohmann::json ms = multiscales(path, GetParam().format);
  EXPECT_EQ(ms["type"], "mean");
  ASSERT_EQ(ms["datasets"].size(), 3u);
  for (int l = 0; l < 3; ++l) {
    SCOPED_TRACE(l);
    const nlohmann::json& t = ms["datasets"][std::size_t(l)]["coordinateTransformations"];
    const double f = double(1 << l);
    // z y x: z kept (2 mm, no shift); y and x scaled by 2^l and shifted by
    // (2^l - 1)/2 of level 0's voxels, along the array's axes (the LPS
    // direction is not in the translation).
    EXPECT_EQ(t[0]["scale"], nlohmann::json({2.0, 0.5 * f, 0.4 * f}));
    EXPECT_EQ(t[1]["translation"],
              nlohmann::json({7.0, 5.0 + 0.5 * ((f - 1) / 2), -3.0 + 0.4 * ((f - 1) / 2)}));
  }

  const auto source = lod::ZarrMultiresSource::open(path.string());
  const ZarrStore& store = source->store();
  ASSERT_EQ(store.levelCount(), 3);
  const std::vector<glm::ivec3> factors = lod::levelFactors(*source);
  for (int l = 0; l < 3; ++l) {
    SCOPED_TRACE(l);
    const glm::ivec3 s(1 << l, 1 << l, 1);
    EXPECT_EQ(lod::levelScale(*source, l), s);
    if (l > 0) {
      EXPECT_EQ(factors[std::size_t(l)], kKeepZ);
    }
    const ZarrLevel& level = store.level(l);
    EXPECT_EQ(level.dims, r.levelDims[std::size_t(l)]);
    EXPECT_EQ(level.spacing, v.spacing() * glm::dvec3(s));
    // Voxel (0,0,0) of level l is where the centre of its block of level 0
    // lies in the world: index (s - 1)/2 of level 0, through the direction.
    const glm::dvec3 want = v.worldOf((glm::dvec3(s) - 1.0) / 2.0);
    EXPECT_NEAR(glm::length(level.origin - want), 0.0, 1e-12)
        << level.origin.x << " " << level.origin.y << " " << level.origin.z;
    const Volume read = store.readLevel(l);
    int differing = 0;
    for (int z = 0; z < level.dims.z; ++z)
      for (int y = 0; y < level.dims.y; ++y)
        for (int x = 0; x < level.dims.x; ++x) {
          if (read.valueAt(x, y, z) != blockMean(v, {x, y, z}, s)) ++differing;
        }
    EXPECT_EQ(differing, 0) << "voxels of level " << l << " differing from their block's mean";
  }
}

// Odd sizes (partial blocks at the edges) in u16: each level the 2x2x1 mean
// of the one before, rounded, as computed here.
TEST_P(ZarrPyramidFactors, OddEdgesAverageTheVoxelsPresent) {
  const test::TempDir tmp;
  const fs::path path = tmp / "odd.ome.zarr";
  const Volume v = ramp({37, 29, 10}, ScalarType::U16);
  const OmeZarrWriteResult r = writeOmeZarr(v, path, keepZ(GetParam()));
  // 37x29 -> 19x15 -> 10x8 -> 5x4: x fits a chunk only at level 3.
  ASSERT_EQ(r.levelDims,
            (std::vector<glm::ivec3>{{37, 29, 10}, {19, 15, 10}, {10, 8, 10}, {5, 4, 10}}));
  const ZarrStore store(std::make_shared<FolderStorage>(path));
  Volume expected = v;
  for (int l = 1; l < store.levelCount(); ++l) {
    SCOPED_TRACE(l);
    expected = meanKeepingZ(expected);
    const Volume read = store.readLevel(l);
    ASSERT_EQ(read.dims(), expected.dims());
    std::size_t differing = 0;
    for (std::size_t i = 0; i < read.voxelCount(); ++i) {
      if (read.valueAtIndex(i) != expected.valueAtIndex(i)) ++differing;
    }
    EXPECT_EQ(differing, 0u);
  }
}

TEST(ZarrPyramidFactorsOption, FactorsOtherThanOneOrTwoAreRefused) {
  const test::TempDir tmp;
  const Volume v = ramp({16, 16, 8}, ScalarType::U8);
  for (const glm::ivec3 f : {glm::ivec3(1), glm::ivec3(2, 3, 1), glm::ivec3(0, 2, 2)}) {
    OmeZarrWriteOptions o;
    o.factors = f;
    try {
      writeOmeZarr(v, tmp / "bad.ome.zarr", o);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("expected Z,Y,X each 1 (axis kept) or 2 (halved)"),
                std::string::npos)
          << e.what();
    }
    EXPECT_FALSE(fs::exists(tmp / "bad.ome.zarr"));
  }
}
