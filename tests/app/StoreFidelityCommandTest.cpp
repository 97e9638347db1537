// Streamed stores at full fidelity, as a user runs them: a store renders
// like the same data read from a file (its default window is the data's
// value range, compressed or not), and `--layout bricks` under a narrow
// window gives the in-core (texture3d) image for f32, u16 and i16 stores.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "support/CliRunner.h"
#include "support/TestSupport.h"
#include "tessera/core/Image.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/VolumeWriter.h"
#include "tessera/reference/ImageMetrics.h"

namespace {

using tessera::Image;
using tessera::test::runCli;
using tessera::test::runCliJson;
using tessera::test::TempDir;

const std::string kInia = "/usr/share/mricron/templates/inia19-t1-brain.nii.gz";

Image render(const TempDir& tmp, const std::string& input, const std::string& options,
             const std::string& name) {
  const auto out = tmp / (name + ".png");
  const auto r = runCli("render " + input + " " + options + " --out " + out.string());
  EXPECT_EQ(r.exitCode, 0) << input << " " << options << ": " << r.err;
  return Image::readPng(out);
}

void convert(const std::string& in, const std::filesystem::path& out,
             const std::string& options = "") {
  const auto r = runCli("convert " + in + " " + out.string() + " --quiet " + options);
  ASSERT_EQ(r.exitCode, 0) << r.err;
}

// A CT-like phantom of `type` (Shepp-Logan over [lo, hi] plus a sub-step
// ramp), written as NIfTI.
std::string phantomFile(const TempDir& tmp, tessera::ScalarType type, double lo, double hi) {
  const tessera::Volume u8 = tessera::makeSheppLogan({96, 80, 72});
  tessera::Volume v = tessera::Volume::allocate(u8.dims(), type);
  for (std::size_t i = 0; i < v.voxelCount(); ++i) {
    const double x = static_cast<double>(i % 96) / 96.0;
    v.setValueAtIndex(i, std::round(lo + (u8.valueAtIndex(i) + 0.9 * x) / 256.0 * (hi - lo)));
  }
  v.invalidateRange();
  const auto path = tmp / (std::string(tessera::scalarTypeName(type)) + ".nii.gz");
  tessera::writeVolume(v, path);
  return path.string();
}

}  // namespace

TEST(StoreFidelity, AStoreRendersLikeTheSameDataReadFromAFile) {
  ASSERT_TRUE(std::filesystem::exists(kInia)) << "mricron-data is installed by scripts/setup.sh";
  const TempDir tmp;
  const std::string u16 = phantomFile(tmp, tessera::ScalarType::U16, 0.0, 60000.0);
  const std::string size = "--size 160x160 --tf grey";
  for (const std::string& file : {std::string("gen:shepp-logan:96"), u16, kInia}) {
    const Image fromFile = render(tmp, file, size, "file");
    for (const std::string compressor : {"zstd", "none"}) {
      const auto store = tmp / ("s-" + compressor + ".ome.zarr");
      std::filesystem::remove_all(store);
      convert(file, store, "--chunk 64 --compressor " + compressor);
      const Image fromStore = render(tmp, store.string(), size, "store");
      ASSERT_EQ(fromFile.rgba().size(), fromStore.rgba().size());
      EXPECT_TRUE(fromFile.rgba() == fromStore.rgba())
          << file << " as a " << compressor << " store: " << tessera::psnr(fromFile, fromStore)
          << " dB, not identical";
    }
  }
}

// The user's case: an f32 brain with a window of 30 of its 383 units. With
// 8-bit bricks over the store's window the bricked image was almost black
// (14.4 dB against texture3d).
TEST(StoreFidelity, BricksHonourANarrowWindowOnAnF32Store) {
  const TempDir tmp;
  const auto store = tmp / "inia.ome.zarr";
  convert(kInia, store, "--chunk 64");
  const std::string opts = "--size 320x320 --window 60 90 --tf grey";
  const Image inCore = render(tmp, store.string(), opts + " --layout texture3d", "t3d");
  const Image bricked = render(tmp, store.string(), opts + " --layout bricks", "bricks");
  const double db = tessera::psnr(inCore, bricked);
  EXPECT_GE(db, 55.0);
  std::printf("  [measured] inia19 f32 store, window 60..90: bricks vs texture3d %.2f dB\n", db);
}

TEST(StoreFidelity, SixteenBitStoresUnderWindowsOfOneTenAndAHundredPercent) {
  const TempDir tmp;
  struct Case {
    tessera::ScalarType type;
    double lo, hi;
  };
  for (const Case& k : {Case{tessera::ScalarType::U16, 0.0, 60000.0},
                        Case{tessera::ScalarType::I16, -1024.0, 3071.0}}) {
    const std::string file = phantomFile(tmp, k.type, k.lo, k.hi);
    const auto store = tmp / (std::string(tessera::scalarTypeName(k.type)) + ".ome.zarr");
    convert(file, store, "--chunk 64");
    for (const double fraction : {0.01, 0.1, 1.0}) {
      const double w = fraction * (k.hi - k.lo);
      const double c = fraction < 1.0 ? k.lo + 0.4 * (k.hi - k.lo) : 0.5 * (k.lo + k.hi);
      const std::string opts = "--size 240x240 --tf grey --window " + std::to_string(c - w / 2) +
                               " " + std::to_string(c + w / 2);
      const Image inCore = render(tmp, store.string(), opts + " --layout texture3d", "t3d");
      const Image bricked = render(tmp, store.string(), opts + " --layout bricks", "bricks");
      const double db = tessera::psnr(inCore, bricked);
      EXPECT_GE(db, 55.0) << tessera::scalarTypeName(k.type) << " window " << fraction;
      std::printf("  [measured] %s store, window %g%% of the range: bricks vs texture3d %.2f dB\n",
                  std::string(tessera::scalarTypeName(k.type)).c_str(), 100.0 * fraction, db);
    }
  }
}

// Both layouts against the CPU reference (which reads the level the bricked
// frame shows) on stores of every type under a narrow window (5 % of the
// range, on the phantom's tissue).
TEST(StoreFidelity, BricksAndTexture3dMatchTheReferenceUnderANarrowWindowOnEveryStoreType) {
  const TempDir tmp;
  struct Case {
    tessera::ScalarType type;
    double lo, hi;
  };
  for (const Case& k :
       {Case{tessera::ScalarType::U8, 0.0, 255.0}, Case{tessera::ScalarType::U16, 0.0, 60000.0},
        Case{tessera::ScalarType::I16, -1024.0, 3071.0},
        Case{tessera::ScalarType::F32, -1024.0, 3071.0}}) {
    const std::string file = phantomFile(tmp, k.type, k.lo, k.hi);
    const auto store = tmp / (std::string(tessera::scalarTypeName(k.type)) + ".ome.zarr");
    convert(file, store, "--chunk 64");
    const double w = 0.05 * (k.hi - k.lo), c = k.lo + 0.4 * (k.hi - k.lo);
    const std::string opts = " --size 160x160 --tf grey --reference --json --window " +
                             std::to_string(c - w / 2) + " " + std::to_string(c + w / 2);
    for (const std::string layout : {"texture3d", "bricks"}) {
      const nlohmann::json j = runCliJson("render " + store.string() + " --layout " + layout +
                                          opts + " --out " + (tmp / "r.png").string());
      const double db = j["psnr_db"].get<double>();
      EXPECT_GE(db, 45.0) << tessera::scalarTypeName(k.type) << " " << layout;
      std::printf("  [measured] %s store, window 5%% of the range, %s vs reference %.2f dB\n",
                  std::string(tessera::scalarTypeName(k.type)).c_str(), layout.c_str(), db);
    }
  }
}
