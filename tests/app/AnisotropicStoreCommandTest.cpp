// `tessera render STORE --layout bricks` for an OME-Zarr store whose levels
// keep z (microscopy's (1, 2, 2) scales, z y x): the frame against the CPU
// reference of the level it shows, composite and MIP, on ES 3 and ES 2, and
// (ES 3) against that level written as NIfTI and rendered in core
// (texture3d) at the same sample distance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/CliRunner.h"
#include "support/TestSupport.h"
#include "tessera/core/Image.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/VolumeWriter.h"
#include "tessera/io/ZarrWriter.h"
#include "tessera/lod/Downsample.h"
#include "tessera/reference/ImageMetrics.h"

using namespace tessera;
using test::runCli;
using test::runCliJson;
using test::TempDir;

namespace {

namespace fs = std::filesystem;

constexpr glm::ivec3 kKeepZ{2, 2, 1};

// 96x80x40 voxels of 0.5 mm, a ramp along z so that a level
// squeezed or stretched along z shows; x and y halve, z is kept: 96x80x40,
// 48x40x40, 24x20x40 (every level's box is level 0's).
std::vector<Volume> levels() {
  const glm::ivec3 d{96, 80, 40};
  const Volume base = makeSheppLogan(d);
  Volume v = Volume::allocate(d, ScalarType::U16, "keeps-z");
  std::size_t i = 0;
  for (int z = 0; z < d.z; ++z)
    for (int y = 0; y < d.y; ++y)
      for (int x = 0; x < d.x; ++x, ++i) {
        v.setValueAtIndex(i, base.valueAtIndex(i) * (0.3 + 0.7 * (z + 0.5) / d.z) * 40.0 + 100.0);
      }
  v.invalidateRange();
  v.setSpacing({0.5, 0.5, 0.5});
  v.setOrigin({-20.0, 4.0, 12.0});
  std::vector<Volume> out;
  out.push_back(std::move(v));
  out.push_back(lod::downsample(out.back(), kKeepZ));
  out.push_back(lod::downsample(out.back(), kKeepZ));
  return out;
}

nlohmann::json zyx(glm::dvec3 v) {
  return {v.z, v.y, v.x};
}

// The levels as one OME-Zarr store: each written by the io writer as a
// store of one level, its array moved under the first's, and the first's
// multiscales given every level's scale and translation (the voxel centres
// lod::downsample put there), as a microscopy pyramid declares them.
std::string keepZStore(const std::vector<Volume>& lv, const TempDir& tmp) {
  const fs::path store = tmp / "keeps-z.ome.zarr";
  OmeZarrWriteOptions o;
  o.chunk = 32;
  o.levels = 1;
  writeOmeZarr(lv[0], store, o);
  for (std::size_t l = 1; l < lv.size(); ++l) {
    const fs::path one = tmp / ("level" + std::to_string(l) + ".ome.zarr");
    writeOmeZarr(lv[l], one, o);
    fs::rename(one / "0", store / std::to_string(l));
  }
  nlohmann::json attrs = nlohmann::json::parse(std::ifstream(store / ".zattrs"));
  nlohmann::json& datasets = attrs["multiscales"][0]["datasets"];
  datasets = nlohmann::json::array();
  for (std::size_t l = 0; l < lv.size(); ++l) {
    datasets.push_back({{"path", std::to_string(l)},
                        {"coordinateTransformations",
                         nlohmann::json::array(
                             {{{"type", "scale"}, {"scale", zyx(lv[l].spacing())}},
                              {{"type", "translation"}, {"translation", zyx(lv[l].origin())}}})}});
  }
  std::ofstream(store / ".zattrs") << attrs.dump(2);
  return store.string();
}

const std::string kView = " --azimuth 30 --elevation 20 --adaptive off --preintegrate off";

}  // namespace

TEST(AnisotropicStoreCommand, BrickedLevelsMatchTheReferenceAndTheLevelRenderedInCore) {
  const TempDir tmp;
  const std::vector<Volume> lv = levels();
  const std::string store = keepZStore(lv, tmp);
  const ValueRange range = lv[0].valueRange();
  const std::string window =
      " --window " + std::to_string(range.min) + " " + std::to_string(range.max);
  // Frames small enough that one level shows everywhere: 1 at 48x40, 2 at 24x20.
  struct Frame {
    int level;
    const char* size;
  };
  for (const Frame f : {Frame{1, "48x40"}, Frame{2, "24x20"}}) {
    for (const char* profile : {"gles3", "gles2"}) {
      for (const char* mode : {"composite", "mip"}) {
        const std::string what = std::string(f.size) + " " + profile + " " + mode;
        const fs::path bricked = tmp / "bricked.png";
        const auto j = runCliJson("render " + store + " --layout bricks --reference --json" +
                                  kView + window + " --step 0.5 --size " + f.size + " --profile " +
                                  profile + " --mode " + mode + " --out " + bricked.string());
        EXPECT_EQ(j["layout"], "bricks") << what;
        EXPECT_TRUE(j["bricks"]["complete"].get<bool>()) << what;
        EXPECT_EQ(j["reference_level"], f.level) << what << ": " << j["reference_level_note"];
        EXPECT_FALSE(j["reference_level_mixed"].get<bool>()) << what;
        const glm::ivec3 d = lv[static_cast<std::size_t>(f.level)].dims();
        EXPECT_EQ(j["reference_level_dims"], nlohmann::json({d.x, d.y, d.z})) << what;
        const double vsRef = j["psnr_db"].get<double>();
        EXPECT_GE(vsRef, 45.0) << what;
        // ES 3: the level as NIfTI, in core, at the bricks' sample distance
        // (0.5 of level 0's smallest spacing, 0.25 mm). (ES 2's mosaic would
        // keep 8 of the u16 values' bits.)
        double vsNifti = 0.0;
        if (std::string(profile) == "gles3") {
          const Volume& level = lv[static_cast<std::size_t>(f.level)];
          const fs::path nifti = tmp / ("level" + std::to_string(f.level) + ".nii.gz");
          if (!fs::exists(nifti)) writeVolume(level, nifti);
          const glm::dvec3 s = level.spacing();
          const double step = 0.25 / std::min({s.x, s.y, s.z});
          const fs::path inCore = tmp / "in-core.png";
          const auto r =
              runCli("render " + nifti.string() + " --layout texture3d" + kView + window +
                     " --step " + std::to_string(step) + " --size " + f.size + " --profile " +
                     profile + " --mode " + mode + " --out " + inCore.string());
          ASSERT_EQ(r.exitCode, 0) << r.err;
          vsNifti = psnr(Image::readPng(bricked), Image::readPng(inCore));
          EXPECT_GE(vsNifti, 45.0) << what;
        }
        std::printf(
            "  [measured] (1, 2, 2) store %s, level %d: bricks vs reference %.2f dB, vs the "
            "level as NIfTI in core %.2f dB (0: not compared)\n",
            what.c_str(), f.level, vsRef, vsNifti);
      }
    }
  }
}

// The same pyramid written by `tessera convert --pyramid-factors 1,2,2`
// (Zarr v3, sharded) from level 0 as NIfTI: each level bricked against
// the reference and against that level (lod::downsample by (1, 2, 2), z y
// x) rendered in core from NIfTI.
TEST(AnisotropicStoreCommand, ConvertWithPyramidFactorsWritesAStoreThatRendersAsItsLevels) {
  const TempDir tmp;
  const std::vector<Volume> lv = levels();
  const fs::path nifti0 = tmp / "level0.nii.gz";
  writeVolume(lv[0], nifti0);
  const fs::path store = tmp / "converted.ome.zarr";
  const auto c =
      runCli("convert " + nifti0.string() + " " + store.string() +
             " --pyramid-factors 1,2,2 --chunk 32,32,32 --zarr-format 3 --shard 2 --quiet");
  ASSERT_EQ(c.exitCode, 0) << c.err;
  EXPECT_NE(c.out.find("3 levels (factors 1,2,2 (z,y,x): 96x80x40, 48x40x40, 24x20x40)"),
            std::string::npos)
      << c.out;
  const ValueRange range = lv[0].valueRange();
  const std::string window =
      " --window " + std::to_string(range.min) + " " + std::to_string(range.max);
  for (const auto& [level, size] : {std::pair{1, "48x40"}, std::pair{2, "24x20"}}) {
    const Volume& lvl = lv[static_cast<std::size_t>(level)];
    const fs::path niftiL = tmp / ("level" + std::to_string(level) + ".nii.gz");
    writeVolume(lvl, niftiL);
    const double step = 0.25 / std::min({lvl.spacing().x, lvl.spacing().y, lvl.spacing().z});
    for (const char* mode : {"composite", "mip"}) {
      const std::string what = std::string(size) + " " + mode;
      const fs::path bricked = tmp / "bricked.png";
      const fs::path inCore = tmp / "in-core.png";
      const auto j = runCliJson("render " + store.string() + " --layout bricks --reference --json" +
                                kView + window + " --step 0.5 --size " + size +
                                " --profile gles3 --mode " + mode + " --out " + bricked.string());
      EXPECT_TRUE(j["bricks"]["complete"].get<bool>()) << what;
      EXPECT_EQ(j["reference_level"], level) << what;
      const auto r = runCli("render " + niftiL.string() + " --layout texture3d" + kView + window +
                            " --step " + std::to_string(step) + " --size " + size +
                            " --profile gles3 --mode " + mode + " --out " + inCore.string());
      ASSERT_EQ(r.exitCode, 0) << r.err;
      const double vsRef = j["psnr_db"].get<double>();
      const double vsNifti = psnr(Image::readPng(bricked), Image::readPng(inCore));
      EXPECT_GE(vsRef, 45.0) << what;
      EXPECT_GE(vsNifti, 45.0) << what;
      std::printf(
          "  [measured] convert --pyramid-factors 1,2,2 (v3, sharded) %s, level %d: bricks vs "
          "reference %.2f dB, vs the level as NIfTI in core %.2f dB\n",
          what.c_str(), level, vsRef, vsNifti);
    }
  }
}

TEST(AnisotropicStoreCommand, PyramidFactorsOtherThanOneOrTwoPerAxisAreRefusedBeforeReading) {
  const TempDir tmp;
  for (const char* bad : {"1,1,1", "1,2,3", "2,2", "z,y,x"}) {
    const auto r = runCli("convert missing.nii.gz " + (tmp / "out.ome.zarr").string() +
                          " --pyramid-factors " + bad);
    EXPECT_NE(r.exitCode, 0) << bad;
    EXPECT_NE(r.err.find("--pyramid-factors '" + std::string(bad) +
                         "': expected Z,Y,X each 1 (axis kept) or 2 (halved), at least one 2"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(tmp / "out.ome.zarr")) << bad;
  }
}
