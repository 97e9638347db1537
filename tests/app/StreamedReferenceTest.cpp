// `tessera render STORE --layout bricks --reference`: a streamed volume's
// frame against the CPU reference of the pyramid level the GPU shows, read
// whole through the same lod::MultiresSource (session/RenderRun.h), for
// stores of every scalar type, a generated head:, the level the refined
// frame shows by default, --reference-level, and the errors a user meets.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "support/CliRunner.h"
#include "support/TestSupport.h"
#include "tessera/core/Volume.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/VolumeWriter.h"

using tessera::ScalarType;
using tessera::Volume;
using tessera::test::expectFailure;
using tessera::test::runCli;
using tessera::test::runCliJson;
using tessera::test::TempDir;

namespace {

// Odd dims that 64-voxel bricks and the halving divide nowhere (levels
// 131x117x101, 66x59x51, 33x30x26), so a level placed half a voxel off
// would show. Stored in 64^3 chunks, so in 64^3 bricks: at 128x112 every
// cell shows level 0, at 40x36 level 1, on both API levels.
const glm::ivec3 kDims{131, 117, 101};
// In 32^3 bricks (its sides under 64 are not one cubic chunk) of two levels,
// 93x77x61 and 47x39x31: the ES 2 atlas (the whole pyramid, 22 bricks)
// cannot hold all of level 0 at once, so a large frame shows both levels.
const glm::ivec3 kSmallDims{93, 77, 61};

// The Shepp-Logan phantom weighted by ramps along x and z (no mirror image
// of it comes close to it) in `type`'s range: u16 and i16 (partly negative)
// well past 8 bits, f32 below 1. Spacing and origin of a real scan.
Volume phantom(ScalarType type, glm::ivec3 d) {
  const Volume base = tessera::makeSheppLogan(d);
  Volume v = Volume::allocate(d, type, "phantom");
  std::size_t i = 0;
  for (int z = 0; z < d.z; ++z) {
    for (int y = 0; y < d.y; ++y) {
      for (int x = 0; x < d.x; ++x, ++i) {
        const double f =
            base.valueAtIndex(i) * (0.3 + 0.7 * (z + 0.5) / d.z) * (0.6 + 0.4 * (x + 0.5) / d.x);
        double raw = f;
        if (type == ScalarType::U16) raw = 37.0 * f + 200.0;
        if (type == ScalarType::I16) raw = 23.0 * f - 1200.0;
        if (type == ScalarType::F32) raw = f / 255.0 * 3.0 - 0.8;
        v.setValueAtIndex(i, raw);
      }
    }
  }
  v.invalidateRange();
  v.setSpacing({0.9, 1.1, 1.3});
  v.setOrigin({-40.0, 12.5, 30.0});
  return v;
}

// The phantom written by the io writer and converted to an OME-Zarr store
// of 64^3 chunks (or `chunk`) by `tessera convert`.
std::string storeOf(ScalarType type, const TempDir& tmp, glm::ivec3 dims = kDims,
                    const std::string& chunk = "64") {
  const std::string name =
      std::string(tessera::scalarTypeName(type)) + "_" + std::to_string(dims.x);
  const auto nrrd = tmp / (name + ".nrrd");
  tessera::writeVolume(phantom(type, dims), nrrd);
  const auto store = tmp / (name + ".ome.zarr");
  const auto r =
      runCli("convert " + nrrd.string() + " " + store.string() + " --chunk " + chunk + " --quiet");
  EXPECT_EQ(r.exitCode, 0) << r.err;
  return store.string();
}

const std::string kView = " --azimuth 30 --elevation 20 --out /dev/null";

nlohmann::json renderStreamed(const std::string& spec, const std::string& options) {
  return runCliJson("render " + spec + " --layout bricks --reference --json" + kView + " " +
                    options);
}

}  // namespace

// The default window (the value range), composite and MIP, on ES 3 (a 3D
// atlas) and ES 2 (the atlas as mosaics of z-slices): bricked against the
// reference of the level shown. The bricks hold 8 bits per voxel, u16/i16/f32
// normalised over the window; narrow windows on those types are left to the
// bricks' own tests.
TEST(StreamedReference, BrickedStoresOfEveryTypeMatchTheReference) {
  const TempDir tmp;
  for (ScalarType type : {ScalarType::U8, ScalarType::U16, ScalarType::I16, ScalarType::F32}) {
    const std::string store = storeOf(type, tmp);
    for (const char* profile : {"gles3", "gles2"}) {
      for (const char* mode : {"composite", "mip"}) {
        const auto j = renderStreamed(
            store, "--size 128x112 --profile " + std::string(profile) + " --mode " + mode);
        const std::string what =
            std::string(tessera::scalarTypeName(type)) + " " + profile + " " + mode;
        EXPECT_EQ(j["layout"], "bricks") << what;
        EXPECT_EQ(j["api"], profile) << what;
        EXPECT_TRUE(j["bricks"]["complete"].get<bool>()) << what;
        // At 128x112 a level-0 voxel covers about a pixel: level 0 everywhere.
        EXPECT_EQ(j["reference_level"], 0) << what << ": " << j["reference_level_note"];
        EXPECT_FALSE(j["reference_level_mixed"].get<bool>()) << what;
        EXPECT_EQ(j["reference_level_dims"], nlohmann::json({131, 117, 101})) << what;
        const double psnr = j["psnr_db"].get<double>();
        const double ssim = j["ssim"].get<double>();
        std::printf("  [measured] %s store, bricks: %.2f dB, SSIM %.4f (level %d)\n", what.c_str(),
                    psnr, ssim, j["reference_level"].get<int>());
        EXPECT_GE(psnr, 45.0) << what;
        EXPECT_GE(ssim, 0.99) << what;
      }
    }
  }
}

// A small frame shows only level 1 (a level-0 voxel would cover less than
// a pixel): the reference reads level 1 by default, and matches only
// because the level lies where bricks.glsl samples it (voxel i centred on
// level-0 index (i + 0.5) 2 - 0.5, the box clamped to level 0's, every side
// odd). The finest level instead, asked for, is another image.
TEST(StreamedReference, TheLevelTheFrameShowsIsTheDefaultAndIsPlacedAsTheGpuShowsIt) {
  const TempDir tmp;
  const std::string store = storeOf(ScalarType::U16, tmp);
  const auto shown = renderStreamed(store, "--size 40x36");
  EXPECT_EQ(shown["reference_level"], 1) << shown["reference_level_note"];
  EXPECT_FALSE(shown["reference_level_mixed"].get<bool>());
  EXPECT_EQ(shown["reference_level_dims"], nlohmann::json({66, 59, 51}));
  EXPECT_NE(shown["reference_level_note"].get<std::string>().find("the level frame 0 shows"),
            std::string::npos)
      << shown["reference_level_note"];
  const double atShown = shown["psnr_db"].get<double>();
  const auto finest = renderStreamed(store, "--size 40x36 --reference-level 0");
  EXPECT_EQ(finest["reference_level"], 0);
  EXPECT_EQ(finest["reference_level_note"], "asked for (--reference-level)");
  const double atFinest = finest["psnr_db"].get<double>();
  std::printf("  [measured] 40x36 frame at level 1: %.2f dB vs level 1, %.2f dB vs level 0\n",
              atShown, atFinest);
  EXPECT_GE(atShown, 45.0);
  EXPECT_LT(atFinest, atShown - 5.0);

  // The text report says which level and why.
  const auto text = runCli("render " + store + " --layout bricks --reference --size 40x36" + kView);
  ASSERT_EQ(text.exitCode, 0) << text.err;
  EXPECT_NE(text.out.find("ref level 1 (66x59x51): the level frame 0 shows"), std::string::npos)
      << text.out;
}

// Whatever the frame shows, the reference level reported is the finest
// level of the page table's cells, and a frame showing several says so and
// is proven cell by cell: on ES 2 the smaller store's level 0 does not fit
// the atlas beside its pinned level 1 at 128x112 (measured: cells L0:10
// L1:8), at 40x36 only level 1 is shown.
TEST(StreamedReference, TheDefaultLevelIsTheFinestShownAndAMixedFrameSaysSo) {
  const TempDir tmp;
  const std::string store = storeOf(ScalarType::U8, tmp, kSmallDims);
  int mixed = 0;
  for (const char* options : {"--size 128x112 --profile gles2", "--size 40x36 --profile gles2",
                              "--size 128x112 --profile gles3"}) {
    const auto j = renderStreamed(store, options);
    const auto cells = j["bricks"]["cells_per_level"];  // the last: transparent cells
    int finest = -1, shown = 0;
    for (std::size_t l = 0; l + 1 < cells.size(); ++l) {
      if (cells[l].get<int>() == 0) continue;
      if (finest < 0) finest = static_cast<int>(l);
      ++shown;
    }
    ASSERT_GE(finest, 0) << options;
    EXPECT_EQ(j["reference_level"], finest) << options;
    EXPECT_EQ(j["reference_level_mixed"].get<bool>(), shown > 1) << options;
    const std::string note = j["reference_level_note"];
    std::printf("  [measured] %s: cells %s, level %d, %.2f dB (%s)\n", options,
                cells.dump().c_str(), finest, j["psnr_db"].get<double>(), note.c_str());
    if (shown > 1) {
      ++mixed;
      EXPECT_EQ(note.rfind("per cell, the level frame 0 shows there (page-table cells L0:", 0), 0u)
          << note;
    }
    EXPECT_GE(j["psnr_db"].get<double>(), 45.0) << options;
  }
  // The bricks' atlas rules decide which frames mix; at least one did here.
  EXPECT_GE(mixed, 1);
}

// A generated head: is always streamed (computed brick by brick); every
// level point-samples the same field, and the reference reads the same.
TEST(StreamedReference, GeneratedHeadMatchesTheReference) {
  const auto j =
      runCliJson("render head:96x80x72 --layout bricks --reference --json --size 112x112" + kView);
  EXPECT_EQ(j["layout"], "bricks");
  ASSERT_TRUE(j.contains("reference_level"));
  const double psnr = j["psnr_db"].get<double>();
  std::printf("  [measured] head:96x80x72, level %d: %.2f dB, SSIM %.4f\n",
              j["reference_level"].get<int>(), psnr, j["ssim"].get<double>());
  EXPECT_GE(psnr, 45.0);
}

// An in-core volume bricked (--layout bricks) takes the same path: the
// pyramid the layout built, level 0 being the volume itself.
TEST(StreamedReference, InCoreVolumeBrickedReportsItsLevel) {
  const auto j = runCliJson(
      "render gen:shepp-logan:96 --layout bricks --reference --json "
      "--size 128x128" +
      kView);
  EXPECT_EQ(j["reference_level"], 0);
  EXPECT_GE(j["psnr_db"].get<double>(), 45.0);
}

// A level whose reference (its voxels and their double copy) exceeds the
// host budget is refused before anything is rendered, naming the level, its
// size, the budget and a level that fits.
TEST(StreamedReference, ALevelOverTheHostBudgetIsRefusedNamingACoarserOne) {
  const TempDir tmp;
  const std::string store = storeOf(ScalarType::U16, tmp, kSmallDims);
  // Level 0: 93x77x61 u16 (853 KiB) + 3.3 MiB of doubles; level 1: 555 KiB.
  setenv("TESSERA_HOST_BUDGET_MB", "3", 1);
  const auto r =
      runCli("render " + store + " --layout bricks --reference-level 0 --size 64x64" + kView);
  unsetenv("TESSERA_HOST_BUDGET_MB");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find("the reference at level 0 (93x77x61 u16, 853.2 KiB)"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("needs 4.2 MiB of host memory"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("over the host budget of 3 MiB"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("choose a coarser level with --reference-level N (level 1 is the finest "
                       "that fits; the pyramid has levels 0..1)"),
            std::string::npos)
      << r.err;
}

TEST(StreamedReference, AReferenceLevelOutOfRangeOrOnAnInCoreLayoutIsRefused) {
  const TempDir tmp;
  const std::string store = storeOf(ScalarType::U8, tmp, kSmallDims);
  for (const char* level : {"2", "-1"}) {
    expectFailure("render " + store + " --layout bricks --reference-level " + level + kView,
                  "--reference-level " + std::string(level) + ": ");
    expectFailure("render " + store + " --layout bricks --reference-level " + level + kView,
                  "has levels 0..1 (0 = the finest)");
  }
  expectFailure("render gen:sphere:32 --layout texture3d --reference-level 0" + kView,
                "--reference-level applies to a layout that streams a pyramid (bricks); "
                "texture3d holds the volume it renders");
}

// A 128^3 store in 32^3 chunks under a profile whose texture budget (2 MiB,
// a 36-brick atlas) holds about a third of level 0's 64 bricks: the refined
// frame shows level 0 where the atlas has room and level 1 elsewhere. The
// reference reads, cell by cell, the level the page table shows there and
// matches the frame; one level for the whole frame (the finest shown, as
// --reference-level 0 asks, what the reference read before) does not.
TEST(StreamedReference, AFrameMixingLevelsIsProvenCellByCell) {
  const TempDir tmp;
  const std::string store = storeOf(ScalarType::U8, tmp, {128, 128, 128}, "32,32,32");
  const auto profile = tmp / "small-atlas.json";
  std::ofstream(profile) << R"({"name": "small-atlas", "note": "test", "api": "gles3",
                               "max_2d_texture_size": 4096, "max_3d_texture_size": 2048,
                               "texture_units": 8, "texture_budget_mb": 2,
                               "host_budget_mb": 1024})";
  const std::string options = "--size 128x128 --profile " + profile.string();
  const auto perCell = renderStreamed(store, options);
  const auto cells = perCell["bricks"]["cells_per_level"];
  ASSERT_GE(cells.size(), 3u) << cells;
  EXPECT_GT(cells[0].get<int>(), 0) << cells;
  EXPECT_GT(cells[1].get<int>(), 0) << cells;
  EXPECT_TRUE(perCell["reference_level_mixed"].get<bool>()) << cells;
  EXPECT_EQ(perCell["reference_level"], 0);
  const std::string note = perCell["reference_level_note"];
  EXPECT_EQ(note.rfind("per cell, the level frame 0 shows there (page-table cells L0:", 0), 0u)
      << note;
  const auto oneLevel = renderStreamed(store, options + " --reference-level 0");
  const double mixedDb = perCell["psnr_db"].get<double>();
  const double oneLevelDb = oneLevel["psnr_db"].get<double>();
  std::printf(
      "  [measured] 128^3 u8, 2 MiB atlas, cells %s: per-cell reference %.2f dB (SSIM "
      "%.4f), level 0 everywhere %.2f dB (SSIM %.4f)\n",
      cells.dump().c_str(), mixedDb, perCell["ssim"].get<double>(), oneLevelDb,
      oneLevel["ssim"].get<double>());
  EXPECT_GE(mixedDb, 45.0);
  EXPECT_LT(oneLevelDb, mixedDb - 3.0);
}

// The levels a mixed frame's reference reads must fit the host budget
// together (each read whole, with its double-precision copy): the smaller
// store on ES 2 at 128x112 shows levels 0 and 1 (4.2 MiB together), so a
// 4 MiB budget stops the reference naming both levels and the one level
// that fits on its own.
TEST(StreamedReference, MixedLevelsOverTheHostBudgetAreRefusedNamingOneThatFits) {
  const TempDir tmp;
  const std::string store = storeOf(ScalarType::U8, tmp, kSmallDims);
  setenv("TESSERA_HOST_BUDGET_MB", "4", 1);
  const auto r = runCli("render " + store + " --layout bricks --reference --size 128x112" +
                        " --profile gles2" + kView);
  unsetenv("TESSERA_HOST_BUDGET_MB");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find("the reference of frame 0's levels (level 0 (93x77x61 u8, 426.6 KiB), "
                       "level 1 (47x39x31 u8, 55.5 KiB) of "),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("needs 4.2 MiB of host memory (each level read whole and a "
                       "double-precision copy), over the host budget of 4 MiB: choose one level "
                       "with --reference-level N (level 0 is the finest that fits; the pyramid "
                       "has levels 0..1)"),
            std::string::npos)
      << r.err;
}
