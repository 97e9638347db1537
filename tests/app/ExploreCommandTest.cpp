// `tessera slice` and `tessera render --region`: slice
// pixels are the voxels they claim (direct indexing), the same anatomy
// gives the same image whatever the storage order (radiological
// convention), stores read only the chunks a slice or region touches, and a
// region renders like the same box cut out with `convert --crop`.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <utility>

#include <nlohmann/json.hpp>

#include "support/CliRunner.h"
#include "support/Nibabel.h"
#include "support/TestSupport.h"
#include "tessera/core/Image.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/io/ZarrWriter.h"
#include "tessera/reference/ImageMetrics.h"

namespace {

using tessera::Image;
using tessera::test::runCli;
using tessera::test::TempDir;

// A 20x16x12 u8 volume with distinct-ish values and a bright marker on the
// patient's right-anterior-superior side, written by nibabel twice: RAS
// storage, and LAS storage (x reversed, same anatomy, same world frame).
constexpr const char* kMarkedVolumes = R"(
import sys, numpy as np, nibabel as nib
x, y, z = np.meshgrid(np.arange(20), np.arange(16), np.arange(12), indexing='ij')
d = ((x * 13 + y * 7 + z * 3) % 250).astype(np.uint8)
d[14:18, 10:14, 8:11] = 255
nib.save(nib.Nifti1Image(d, np.eye(4)), sys.argv[1] + '/ras.nii')
las = np.diag([-1.0, 1, 1, 1]); las[0, 3] = 19
nib.save(nib.Nifti1Image(d[::-1].copy(), las), sys.argv[1] + '/las.nii')
nib.save(nib.Nifti1Image(d, np.diag([0.5, 1, 2, 1])), sys.argv[1] + '/aniso.nii')
)";

class ExploreCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    if (auto why = tessera::test::nibabelMissing()) GTEST_SKIP() << *why;
    tessera::test::runPython(tmp, kMarkedVolumes, tmp.path().string());
  }
  std::string file(const char* name) const { return (tmp / name).string(); }
  // ras.nii as an OME-Zarr store in 8^3 chunks (the CLI writes 64 or 128).
  std::filesystem::path writeStore() const {
    const auto store = tmp / "s.ome.zarr";
    tessera::OmeZarrWriteOptions options;
    options.chunk = 8;
    tessera::writeOmeZarr(tessera::readVolume(file("ras.nii")), store, options);
    return store;
  }
  TempDir tmp;
};

struct Slice {
  nlohmann::json report;
  Image image;
};

Slice slice(const std::string& args, const std::filesystem::path& out) {
  const auto r = runCli("slice " + args + " --window 0 255 --json --out " + out.string());
  EXPECT_EQ(r.exitCode, 0) << r.err;
  return {nlohmann::json::parse(r.out), Image::readPng(out)};
}

int axisOf(const nlohmann::json& name) {
  return name.get<std::string>()[0] - 'x';
}

// Every pixel equals the voxel its row and column name (isotropic spacing:
// one pixel per voxel), read back from the file by the reader.
void expectPixelsAreVoxels(const std::string& path, int axis, int index, const Slice& s) {
  const tessera::Volume v = tessera::readVolume(path);
  const int colAxis = axisOf(s.report["columns"]["axis"]);
  const int rowAxis = axisOf(s.report["rows"]["axis"]);
  ASSERT_EQ(s.image.width(), v.dims()[colAxis]);
  ASSERT_EQ(s.image.height(), v.dims()[rowAxis]);
  int mismatches = 0;
  for (int row = 0; row < s.image.height(); ++row) {
    for (int col = 0; col < s.image.width(); ++col) {
      glm::ivec3 p(0);
      p[axis] = index;
      p[colAxis] = s.report["columns"]["reversed"] ? v.dims()[colAxis] - 1 - col : col;
      p[rowAxis] = s.report["rows"]["reversed"] ? v.dims()[rowAxis] - 1 - row : row;
      const std::uint8_t* px = s.image.pixel(col, row);
      if (px[0] != v.valueAt(p.x, p.y, p.z) || px[1] != px[0] || px[2] != px[0]) ++mismatches;
    }
  }
  EXPECT_EQ(mismatches, 0) << path << " axis " << axis;
}

bool sameImage(const Image& a, const Image& b) {
  if (a.width() != b.width() || a.height() != b.height()) return false;
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) {
      for (int c = 0; c < 4; ++c) {
        if (a.pixel(x, y)[c] != b.pixel(x, y)[c]) return false;
      }
    }
  }
  return true;
}

// Mean column and row of the marker's pixels (value 255).
glm::dvec2 markerCentre(const Image& im) {
  glm::dvec2 sum(0.0);
  int n = 0;
  for (int y = 0; y < im.height(); ++y) {
    for (int x = 0; x < im.width(); ++x) {
      if (im.pixel(x, y)[0] == 255) {
        sum += glm::dvec2(x, y);
        ++n;
      }
    }
  }
  EXPECT_GT(n, 0);
  return n ? sum / double(n) : glm::dvec2(-1.0);
}

TEST_F(ExploreCommand, SlicePixelsAreTheVoxelsTheyClaimForEveryAxisAndStorage) {
  const char* axes[] = {"x", "y", "z"};
  const int index[] = {15, 11, 9};  // through the marker
  for (const char* name : {"ras.nii", "las.nii"}) {
    for (int a = 0; a < 3; ++a) {
      const Slice s =
          slice(file(name) + " --axis " + axes[a] + " --index " + std::to_string(index[a]),
                tmp / "s.png");
      expectPixelsAreVoxels(file(name), a, index[a], s);
    }
  }
}

TEST_F(ExploreCommand, SameAnatomyGivesTheSameRadiologicalImageWhateverTheStorage) {
  // LAS stores x reversed: RAS x = 15 is LAS x = 19 - 15.
  const char* args[][2] = {{"--axis x --index 15", "--axis x --index 4"},
                           {"--axis y --index 11", "--axis y --index 11"},
                           {"--axis z --index 9", "--axis z --index 9"}};
  const char* plane[] = {"sagittal", "coronal", "axial"};
  for (int a = 0; a < 3; ++a) {
    const Slice ras = slice(file("ras.nii") + " " + args[a][0], tmp / "ras.png");
    const Slice las = slice(file("las.nii") + " " + args[a][1], tmp / "las.png");
    EXPECT_TRUE(sameImage(ras.image, las.image)) << plane[a];
    EXPECT_EQ(ras.report["plane"], plane[a]);
    EXPECT_EQ(ras.report["edges"], las.report["edges"]) << plane[a];
    const glm::dvec2 m = markerCentre(las.image);
    const double w = las.image.width(), h = las.image.height();
    if (a == 0) {  // sagittal: anterior on the left, superior up
      EXPECT_EQ(las.report["edges"]["left"], "A");
      EXPECT_EQ(las.report["edges"]["top"], "S");
      EXPECT_LT(m.x, w / 2);
      EXPECT_LT(m.y, h / 2);
    } else {  // axial and coronal: the patient's right on the image's left
      EXPECT_EQ(las.report["edges"]["left"], "R");
      EXPECT_EQ(las.report["edges"]["right"], "L");
      EXPECT_EQ(las.report["edges"]["top"], a == 2 ? "A" : "S");
      EXPECT_LT(m.x, w / 2) << plane[a];
      EXPECT_LT(m.y, h / 2) << plane[a];  // anterior (axial) or superior (coronal) up
    }
  }
}

// Spacing 0.5 x 1 x 2 mm: square pixels of the finer in-plane spacing, each
// the voxel whose extent holds the pixel's centre.
TEST_F(ExploreCommand, AnisotropicSlicesKeepTheAspectWithNearestVoxels) {
  const tessera::Volume v = tessera::readVolume(file("aniso.nii"));
  const glm::dvec3 spacing(0.5, 1.0, 2.0);
  for (const auto& [axis, index] : {std::pair{2, 9}, std::pair{0, 15}}) {
    const Slice s = slice(file("aniso.nii") + " --axis " + std::string(1, char('x' + axis)) +
                              " --index " + std::to_string(index),
                          tmp / "a.png");
    const int colAxis = axisOf(s.report["columns"]["axis"]);
    const int rowAxis = axisOf(s.report["rows"]["axis"]);
    const double pixelMm = std::min(spacing[colAxis], spacing[rowAxis]);
    EXPECT_DOUBLE_EQ(s.report["pixel_mm"].get<double>(), pixelMm);
    ASSERT_EQ(s.image.width(), int(std::lround(v.dims()[colAxis] * spacing[colAxis] / pixelMm)));
    ASSERT_EQ(s.image.height(), int(std::lround(v.dims()[rowAxis] * spacing[rowAxis] / pixelMm)));
    int mismatches = 0;
    for (int row = 0; row < s.image.height(); ++row) {
      for (int col = 0; col < s.image.width(); ++col) {
        glm::ivec3 p(0);
        p[axis] = index;
        p[colAxis] = int((col + 0.5) * pixelMm / spacing[colAxis]);
        p[rowAxis] = int((row + 0.5) * pixelMm / spacing[rowAxis]);
        if (s.report["columns"]["reversed"]) p[colAxis] = v.dims()[colAxis] - 1 - p[colAxis];
        if (s.report["rows"]["reversed"]) p[rowAxis] = v.dims()[rowAxis] - 1 - p[rowAxis];
        if (s.image.pixel(col, row)[0] != v.valueAt(p.x, p.y, p.z)) ++mismatches;
      }
    }
    EXPECT_EQ(mismatches, 0) << "axis " << axis;
  }
}

TEST_F(ExploreCommand, BadAxisIndexOrLevelFailsWithOneLine) {
  auto r = runCli("slice " + file("ras.nii") + " --axis w --index 1 --out /dev/null");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find("--axis 'w': expected x, y or z"), std::string::npos) << r.err;
  r = runCli("slice " + file("ras.nii") + " --axis z --index 12 --out /dev/null");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find("--index 12 is outside 0..11 for axis z of " + file("ras.nii")),
            std::string::npos)
      << r.err;
  r = runCli("slice " + file("ras.nii") + " --axis z --index 1 --level 7 --out /dev/null");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find("--level '7'"), std::string::npos) << r.err;
  r = runCli("render " + file("ras.nii") + " --region 3:2,0:4,0:4 --out /dev/null");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find("--region '3:2,0:4,0:4': x range 3:2 is empty"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

TEST_F(ExploreCommand, StoreSliceReadsOnlyTheChunksItTouches) {
  const auto store = writeStore();
  // 20x16x12 in 8^3 chunks: 3x2x2 = 12; a z slice touches 3x2x1 = 6.
  const Slice s = slice(store.string() + " --axis z --index 9", tmp / "z.png");
  EXPECT_EQ(s.report["chunks_in_level"], 12);
  EXPECT_EQ(s.report["chunks_touched"], 6);
  EXPECT_EQ(s.report["chunks_read"], 6);
  EXPECT_GT(s.report["chunk_bytes_read"].get<std::uint64_t>(), 0u);
  expectPixelsAreVoxels(file("ras.nii"), 2, 9, s);
  const Slice x = slice(store.string() + " --axis x --index 3", tmp / "x.png");
  EXPECT_EQ(x.report["chunks_read"], 4);  // 1x2x2
  expectPixelsAreVoxels(file("ras.nii"), 0, 3, x);
}

TEST_F(ExploreCommand, RegionRendersLikeTheCroppedVolumeAndReadsOnlyItsChunks) {
  const std::string box = "3:17,2:13,5:12";
  const std::string view = " --window 0 255 --tf bench --size 96x96 --azimuth 30 --elevation 20";
  ASSERT_EQ(
      runCli("convert " + file("ras.nii") + " " + file("crop.nii") + " --crop " + box).exitCode, 0);
  const auto cropped = runCli("render " + file("crop.nii") + view + " --out " + file("c.png"));
  ASSERT_EQ(cropped.exitCode, 0) << cropped.err;
  const auto region = runCli("render " + file("ras.nii") + " --region " + box + view +
                             " --json --out " + file("r.png"));
  ASSERT_EQ(region.exitCode, 0) << region.err;
  const double db = tessera::psnr(Image::readPng(file("c.png")), Image::readPng(file("r.png")));
  EXPECT_GE(db, 60.0);
  RecordProperty("region_vs_crop_db", std::to_string(db));
  std::printf("region vs crop: %.2f dB\n", db);

  const auto store = writeStore();
  const auto fromStore = runCli("render " + store.string() + " --region " + box + view +
                                " --json --out " + file("z.png"));
  ASSERT_EQ(fromStore.exitCode, 0) << fromStore.err;
  const auto j = nlohmann::json::parse(fromStore.out)["region"];
  // x 3:17 -> chunks 0..2, y 2:13 -> 0..1, z 5:12 -> 0..1: all 12 of 12
  // here, so a narrower box checks the bound below.
  EXPECT_EQ(j["chunks_read"], j["chunks_touched"]);
  const double storeDb =
      tessera::psnr(Image::readPng(file("c.png")), Image::readPng(file("z.png")));
  EXPECT_GE(storeDb, 60.0);
  std::printf("store region vs crop: %.2f dB, %s\n", storeDb, j.dump().c_str());
  const auto narrow = runCli("render " + store.string() + " --region 5:11,1:7,9:12" + view +
                             " --json --out /dev/null");
  ASSERT_EQ(narrow.exitCode, 0) << narrow.err;
  const auto n = nlohmann::json::parse(narrow.out)["region"];
  EXPECT_EQ(n["chunks_touched"], 2);  // x 5:11 -> chunks 0-1, y 1:7 -> 0, z 9:12 -> 1
  EXPECT_EQ(n["chunks_read"], 2);
  EXPECT_EQ(n["chunks_in_level"], 12);
  EXPECT_EQ(n["voxels_read"], 6 * 6 * 3);

  // Level 1 (10x8x6 in 8^3 chunks: 2 chunks): a box in its first chunk
  // reads that one chunk.
  const auto coarse = runCli("render " + store.string() + " --region 0:4,0:4,0:3 --level 1" + view +
                             " --json --out /dev/null");
  ASSERT_EQ(coarse.exitCode, 0) << coarse.err;
  const auto c = nlohmann::json::parse(coarse.out)["region"];
  EXPECT_EQ(c["level"], 1);
  EXPECT_EQ(c["level_dims"], nlohmann::json::array({10, 8, 6}));
  EXPECT_EQ(c["chunks_in_level"], 2);
  EXPECT_EQ(c["chunks_read"], 1);
}

}  // namespace
