// The overlay in the slice views of an OME-Zarr store (docs/fusion.md,
// session/Fusion.h fuseSliceImage over a pyramid): aal over a ch2 store (as
// `tessera convert` writes it), its slices read at a level of the store
// (viewer::SliceGeometry, what the page shows) and the atlas resampled onto
// each level's slice grid by world coordinates. Level 0 equals the file's
// slice views in memory byte for byte; at every level each pixel carries the
// label of the atlas voxel at its level voxel's centre (placed through
// level 0's affine independently here), and the crosshair's positions on
// the postcentral gyri show Postcentral_R at x > 0 mm and Postcentral_L at
// x < 0 mm (RAS+: left and right not swapped).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

#include <glm/common.hpp>
#include <glm/mat4x4.hpp>

#include "support/MricronAtlas.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/io/ZarrWriter.h"
#include "tessera/lod/ZarrMultiresSource.h"
#include "tessera/reference/FusedVolume.h"
#include "tessera/session/Fusion.h"
#include "tessera/viewer/SliceView.h"

namespace tessera::session {
namespace {

using test::aalLabels;
using test::haveMricron;
using test::kAal;
using test::kAalNames;
using test::kCh2;
const glm::dvec3 kRightPostcentral{40.0, -25.0, 52.0};
const glm::dvec3 kLeftPostcentral{-40.0, -25.0, 52.0};

using Rgb = std::array<int, 3>;
Rgb rgbAt(const Image& image, glm::ivec2 px) {
  const std::uint8_t* p = image.pixel(px.x, px.y);
  return {p[0], p[1], p[2]};
}

// Label id by its colour in the table (opaque overlay over black pixels:
// the pixel is the label's colour). -1 when two labels share a colour.
std::map<Rgb, int> idsByColour(const Overlay& o) {
  std::map<Rgb, int> ids;
  for (const auto& [value, label] : o.labels.labels) {
    const Rgb c{static_cast<int>(std::lround(label.color.r * 255.0)),
                static_cast<int>(std::lround(label.color.g * 255.0)),
                static_cast<int>(std::lround(label.color.b * 255.0))};
    ids[c] = ids.count(c) ? -1 : value;
  }
  return ids;
}

int idNamed(const Overlay& o, const std::string& name) {
  for (const auto& [value, label] : o.labels.labels) {
    if (label.name == name) return value;
  }
  return -1;
}

class FusionStoreSlice : public test::Ch2StoreSuite {};

// The level voxel holding a world position (levels span level 0's box).
glm::ivec3 levelVoxelAt(const lod::MultiresSource& src, int level, glm::dvec3 worldMm) {
  const Volume& shape = src.shape();
  const glm::dvec3 i0 = indexOfWorld(shape, worldMm);
  const glm::dvec3 d0(shape.dims()), dl(src.levelInfo(level).dims);
  return glm::ivec3(glm::floor((i0 + 0.5) * dl / d0));
}

TEST_F(FusionStoreSlice, LevelZeroEqualsTheFilesSliceViewsByteForByte) {
  const Volume ch2 = readVolume(kCh2);
  const Overlay onFile = openOverlay(kAal, aalLabels(0.6), ch2);
  const auto src = lod::ZarrMultiresSource::open(store());
  const Overlay onStore = openOverlay(kAal, aalLabels(0.6), src->shape());
  ASSERT_EQ(src->shape().dims(), ch2.dims());
  const lod::LevelInfo l0 = src->levelInfo(0);
  const glm::ivec3 cross(glm::floor(indexOfWorld(ch2, kRightPostcentral) + 0.5));
  for (int axis = 0; axis < 3; ++axis) {
    const viewer::SliceGeometry g(l0.dims, glm::dvec3(l0.spacing), src->shape().direction(), axis);
    const SliceFrame& f = g.frame();
    Image file = sliceImage(ch2, f, cross[axis], ch2.window());
    const Image plain = file;
    fuseSliceImage(file, ch2, f, cross[axis], onFile);
    Image store = g.render(*src, 0, cross[axis], ch2.window(), nullptr);
    fuseSliceImage(store, *src, 0, f, cross[axis], onStore);
    ASSERT_EQ(store.width(), file.width());
    ASSERT_EQ(store.height(), file.height());
    int differ = 0, coloured = 0;
    for (int y = 0; y < file.height(); ++y) {
      for (int x = 0; x < file.width(); ++x) {
        differ += rgbAt(store, {x, y}) != rgbAt(file, {x, y});
        coloured += rgbAt(file, {x, y}) != rgbAt(plain, {x, y});
      }
    }
    std::printf("%s slice %d (%dx%d): %d pixels coloured by aal, %d differ store vs file\n",
                f.plane.c_str(), cross[axis], file.width(), file.height(), coloured, differ);
    EXPECT_EQ(differ, 0) << f.plane;
    EXPECT_GT(coloured, file.width() * file.height() / 20) << f.plane;
  }
}

// Opaque labels over black: each pixel's colour is its label's. Level 1
// (coarser than aal's grid) checks the resampling by world coordinates.
TEST_F(FusionStoreSlice, EveryLevelsPixelsCarryTheAtlasLabelAtTheirVoxelCentre) {
  const auto src = lod::ZarrMultiresSource::open(store());
  ASSERT_GE(src->levelCount(), 2);
  const Overlay o = openOverlay(kAal, aalLabels(1.0), src->shape());
  const std::map<Rgb, int> ids = idsByColour(o);
  const Volume& aal = *o.fused->volume;
  const Volume& shape = src->shape();
  const int right = idNamed(o, "Postcentral_R"), left = idNamed(o, "Postcentral_L");
  ASSERT_GT(right, 0);
  ASSERT_GT(left, 0);
  for (int level : {0, 1}) {
    const lod::LevelInfo li = src->levelInfo(level);
    const glm::ivec3 vr = levelVoxelAt(*src, level, kRightPostcentral);
    const glm::ivec3 vl = levelVoxelAt(*src, level, kLeftPostcentral);
    for (int axis = 0; axis < 3; ++axis) {
      const viewer::SliceGeometry g(li.dims, glm::dvec3(li.spacing), shape.direction(), axis);
      const glm::ivec2 size = g.imageSize();
      Image image(size.x, size.y);
      fuseSliceImage(image, *src, level, g.frame(), vr[axis], o);
      // Each pixel against the atlas voxel at its level voxel's centre.
      int wrong = 0, labelled = 0;
      for (int y = 0; y < size.y; ++y) {
        for (int x = 0; x < size.x; ++x) {
          const glm::dvec3 v(g.voxelAt({x, y}, vr[axis]));
          const glm::dvec3 i0 = (v + 0.5) * glm::dvec3(shape.dims()) / glm::dvec3(li.dims) - 0.5;
          const glm::dvec3 world(shape.indexToWorld() * glm::dvec4(i0, 1.0));
          const glm::ivec3 a(glm::floor(indexOfWorld(aal, world) + 0.5));
          const bool inside = glm::all(glm::greaterThanEqual(a, glm::ivec3(0))) &&
                              glm::all(glm::lessThan(a, aal.dims()));
          const int expected =
              inside ? static_cast<int>(std::lround(aal.valueAt(a.x, a.y, a.z))) : 0;
          const Rgb c = rgbAt(image, {x, y});
          const int shown = c == Rgb{0, 0, 0} ? 0 : (ids.count(c) ? ids.at(c) : -2);
          wrong += shown != expected;
          labelled += shown > 0;
        }
      }
      const auto at = [&](glm::ivec3 v) {
        const Rgb c = rgbAt(image, g.pixelOf(v));
        return ids.count(c) ? ids.at(c) : 0;
      };
      const glm::dvec3 wr(
          shape.indexToWorld() *
          glm::dvec4((glm::dvec3(vr) + 0.5) * glm::dvec3(shape.dims()) / glm::dvec3(li.dims) - 0.5,
                     1.0));
      std::printf(
          "level %d %s slice %d (%dx%d): %d labelled pixels, %d not the atlas's; "
          "crosshair at x = %.1f mm: label %d\n",
          level, g.frame().plane.c_str(), vr[axis], size.x, size.y, labelled, wrong, wr.x, at(vr));
      EXPECT_EQ(wrong, 0) << "level " << level << " " << g.frame().plane;
      EXPECT_GT(labelled, size.x * size.y / 20);
      EXPECT_EQ(at(vr), right) << "level " << level << " " << g.frame().plane;
      EXPECT_GT(wr.x, 0.0);  // RAS+: the patient's right is +x
      if (vl[axis] == vr[axis]) {
        EXPECT_EQ(at(vl), left) << "level " << level;
      }
    }
  }
}

TEST_F(FusionStoreSlice, ALevelOrSliceOutsideThePyramidIsAnError) {
  const auto src = lod::ZarrMultiresSource::open(store());
  const Overlay o = openOverlay(kAal, aalLabels(0.6), src->shape());
  const lod::LevelInfo l0 = src->levelInfo(0);
  const viewer::SliceGeometry g(l0.dims, glm::dvec3(l0.spacing), src->shape().direction(), 2);
  Image image(g.imageSize().x, g.imageSize().y);
  EXPECT_THROW(fuseSliceImage(image, *src, src->levelCount(), g.frame(), 0, o), InputError);
  EXPECT_THROW(fuseSliceImage(image, *src, 0, g.frame(), l0.dims.z, o), InputError);
  Image small(4, 4);
  try {
    fuseSliceImage(small, *src, 0, g.frame(), 0, o);
    ADD_FAILURE() << "a 4x4 image was taken for a " << g.imageSize().x << "x" << g.imageSize().y
                  << " slice";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("the image is 4x4"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tessera::session
