// The slice views, crosshair, bread-slice region and grid block of the
// viewers: slice images against direct indexing, patient letters
// and an asymmetric marker for two storage orders, exact pixel <-> voxel
// mappings, and bounded region reads counted at the source.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <memory>
#include <utility>

#include "support/GpuTestContext.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/io/VolumeWriter.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/viewer/Explorer.h"
#include "tessera/viewer/SliceView.h"
#include "tessera/viewer/Viewer.h"

namespace tessera::viewer {
namespace {

std::shared_ptr<Volume> hashVolume(glm::ivec3 dims, glm::dvec3 spacing, const glm::dmat3& dir) {
  auto v = std::make_shared<Volume>(Volume::allocate(dims, ScalarType::U8));
  for (std::size_t i = 0; i < v->voxelCount(); ++i) {
    v->setValueAtIndex(i, static_cast<double>((i * 2654435761u >> 7) % 251));
  }
  v->setSpacing(spacing);
  v->setDirection(dir);
  v->setGeometrySource("test");
  return v;
}

// Reads through another source and counts the voxels every readBox returns.
class CountingSource final : public lod::MultiresSource {
 public:
  explicit CountingSource(std::shared_ptr<const lod::MultiresSource> inner)
      : inner_(std::move(inner)) {}
  const Volume& shape() const override { return inner_->shape(); }
  int levelCount() const override { return inner_->levelCount(); }
  lod::LevelInfo levelInfo(int level) const override { return inner_->levelInfo(level); }
  Volume readBox(int level, const lod::VoxelBox& box) const override {
    voxels += box.count();
    ++reads;
    return inner_->readBox(level, box);
  }
  std::string describe() const override { return "counting"; }
  mutable std::atomic<std::uint64_t> voxels{0};
  mutable std::atomic<int> reads{0};

 private:
  std::shared_ptr<const lod::MultiresSource> inner_;
};

const glm::dmat3 kRas(1.0);
const glm::dmat3 kLpi(glm::dvec3(-1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, -1));

TEST(SliceView, ImageEqualsDirectIndexingAtVoxelCentres) {
  // Anisotropic spacing and a mirrored storage order: pixels are square
  // (of the finer in-plane spacing), so a coarse voxel covers several.
  for (const glm::dmat3& dir : {kRas, kLpi}) {
    auto vol = hashVolume({13, 9, 7}, {0.5, 1.0, 1.5}, dir);
    const lod::InCoreMultiresSource source(vol);
    for (int axis = 0; axis < 3; ++axis) {
      const SliceGeometry g(vol->dims(), vol->spacing(), dir, axis);
      const int index = vol->dims()[axis] / 2;
      const Image img = g.render(source, 0, index, {0.0, 255.0}, nullptr);
      ASSERT_EQ(img.width(), g.imageSize().x);
      const SliceFrame& f = g.frame();
      for (int row = 0; row < img.height(); ++row) {
        for (int col = 0; col < img.width(); ++col) {
          // Independently: the voxel whose extent holds the pixel centre.
          auto voxel = [&](int pixel, int a, bool reversed) {
            const double mm = (pixel + 0.5) * g.pixelMm();
            int t = 0;
            while (t + 1 < vol->dims()[a] && mm >= (t + 1) * vol->spacing()[a]) ++t;
            return reversed ? vol->dims()[a] - 1 - t : t;
          };
          glm::ivec3 v(0);
          v[axis] = index;
          v[f.colAxis] = voxel(col, f.colAxis, f.colReversed);
          v[f.rowAxis] = voxel(row, f.rowAxis, f.rowReversed);
          ASSERT_EQ(img.pixel(col, row)[0], static_cast<int>(vol->valueAt(v.x, v.y, v.z)))
              << "axis " << axis << " pixel " << col << "," << row;
        }
      }
    }
  }
}

TEST(SliceView, RadiologicalLettersForRasStorage) {
  const SliceFrame axial = sliceFrame(kRas, 2);
  EXPECT_EQ(axial.plane, "axial");
  EXPECT_EQ(axial.left + axial.right + axial.top + axial.bottom, "RLAP");
  const SliceFrame coronal = sliceFrame(kRas, 1);
  EXPECT_EQ(coronal.plane, "coronal");
  EXPECT_EQ(coronal.left + coronal.right + coronal.top + coronal.bottom, "RLSI");
  const SliceFrame sagittal = sliceFrame(kRas, 0);
  EXPECT_EQ(sagittal.plane, "sagittal");
  EXPECT_EQ(sagittal.left + sagittal.right + sagittal.top + sagittal.bottom, "APSI");
  // LPI storage gives the same letters: they are patient directions.
  for (int axis = 0; axis < 3; ++axis) {
    const SliceFrame a = sliceFrame(kRas, axis), b = sliceFrame(kLpi, axis);
    EXPECT_EQ(a.left + a.right + a.top + a.bottom, b.left + b.right + b.top + b.bottom);
  }
  EXPECT_EQ(axisForPlane(kRas, "sagittal"), 0);
  EXPECT_EQ(axisForPlane(kRas, "axial"), 2);
  // Axial slices of a volume stored coronally (k -> anterior) are along j.
  const glm::dmat3 coronalStack(glm::dvec3(1, 0, 0), glm::dvec3(0, 0, -1), glm::dvec3(0, 1, 0));
  EXPECT_EQ(axisForPlane(coronalStack, "axial"), 1);
  EXPECT_EQ(sliceFrame(coronalStack, 2).plane, "coronal");
}

// A volume of `dims` stored with `dir` (RAS or LPI) whose bright cube sits
// at the patient's right-anterior-superior corner, whatever the storage.
Volume markerVolume(glm::ivec3 dims, const glm::dmat3& dir) {
  Volume vol = Volume::allocate(dims, ScalarType::U8);
  vol.setDirection(dir);
  vol.setGeometrySource("test");
  const bool ras = dir == kRas;
  for (int z = 0; z < dims.z; ++z) {
    for (int y = 0; y < dims.y; ++y) {
      for (int x = 0; x < dims.x; ++x) {
        const int wx = ras ? x : dims.x - 1 - x, wy = ras ? y : dims.y - 1 - y,
                  wz = ras ? z : dims.z - 1 - z;
        const bool marker = wx >= dims.x - 5 && wy >= dims.y - 5 && wz >= dims.z - 5;
        vol.setValueAtIndex(vol.index(x, y, z), marker ? 255.0 : 10.0);
      }
    }
  }
  return vol;
}

// Where the bright pixels of every slice view through the marker lie, as
// fractions of the image (x from the left, y from the top).
void expectMarkerTopLeft(const Volume& volume, const std::string& what) {
  auto shared = std::make_shared<Volume>(volume);
  const lod::InCoreMultiresSource source(shared);
  // The marker's voxel nearest the RAS corner: where index -> world is largest.
  glm::ivec3 marker(0);
  for (int a = 0; a < 3; ++a) {
    const glm::dvec3 col = volume.direction()[a];
    const double toward = col.x + col.y + col.z;  // > 0: the index grows towards R, A or S
    marker[a] = toward > 0.0 ? volume.dims()[a] - 2 : 1;
  }
  for (int axis = 0; axis < 3; ++axis) {
    const SliceGeometry g(volume.dims(), volume.spacing(), volume.direction(), axis);
    const Image img = g.render(source, 0, marker[axis], {0.0, 255.0}, nullptr);
    double sx = 0.0, sy = 0.0, n = 0.0;
    for (int row = 0; row < img.height(); ++row) {
      for (int col = 0; col < img.width(); ++col) {
        if (img.pixel(col, row)[0] > 128) {
          sx += col;
          sy += row;
          n += 1.0;
        }
      }
    }
    ASSERT_GT(n, 0.0) << what << " axis " << axis;
    EXPECT_LT(sx / n, 0.5 * img.width()) << what << " " << g.frame().plane;
    EXPECT_LT(sy / n, 0.5 * img.height()) << what << " " << g.frame().plane;
    // And the crosshair at the marker's voxel sits in that quadrant too.
    const glm::dvec2 c = g.pointOf(marker);
    EXPECT_LT(c.x, 0.5 * img.width()) << what << " " << g.frame().plane;
    EXPECT_LT(c.y, 0.5 * img.height()) << what << " " << g.frame().plane;
  }
}

// A bright cube at the patient's right-anterior-superior corner, stored RAS
// and LPI (every index axis reversed), and written as NIfTI (RAS srow), NRRD
// (LPS space directions) and a DICOM series (LPS IOP/IPP), read back: every
// slice view shows it in its top-left quadrant (R on the left of axial and
// coronal, A on the left of sagittal; A up in axial, S up in coronal and
// sagittal).
TEST(SliceView, MarkerAtRightAnteriorSuperiorIsTopLeftInEveryView) {
  const glm::ivec3 dims(20, 24, 16);
  test::TempDir dir;
  for (const glm::dmat3& storage : {kRas, kLpi}) {
    const Volume vol = markerVolume(dims, storage);
    const std::string order = storage == kRas ? "RAS" : "LPI";
    expectMarkerTopLeft(vol, order + " in memory");
    for (const std::string ext : {".nii", ".nrrd", ".dcm.d"}) {
      const auto path = dir / (order + ext);
      writeVolume(vol, path);
      expectMarkerTopLeft(readVolume(path.string()), order + ext);
    }
  }
}

TEST(SliceView, CrosshairPixelVoxelMappingIsExact) {
  const glm::ivec3 dims(31, 17, 11);
  const glm::dvec3 spacing(0.7, 1.9, 3.1);
  for (const glm::dmat3& dir : {kRas, kLpi}) {
    for (int axis = 0; axis < 3; ++axis) {
      const SliceGeometry g(dims, spacing, dir, axis);
      const SliceFrame& f = g.frame();
      for (int r = 0; r < dims[f.rowAxis]; ++r) {
        for (int c = 0; c < dims[f.colAxis]; ++c) {
          glm::ivec3 v(0);
          v[axis] = 3;
          v[f.colAxis] = c;
          v[f.rowAxis] = r;
          ASSERT_EQ(g.voxelAt(g.pixelOf(v), 3), v);
        }
      }
      // And every pixel's voxel maps back to a pixel of the same voxel.
      for (int y = 0; y < g.imageSize().y; ++y) {
        for (int x = 0; x < g.imageSize().x; ++x) {
          const glm::ivec3 v = g.voxelAt({x, y}, 3);
          ASSERT_EQ(g.voxelAt(g.pixelOf(v), 3), v);
        }
      }
    }
  }
  // Screen <-> image: a letterboxed viewport maps pixel centres both ways.
  const SliceViewport vp = SliceViewport::fit({40, 20}, {100.0, 50.0}, {300.0, 300.0});
  EXPECT_DOUBLE_EQ(vp.scale, 7.5);
  EXPECT_DOUBLE_EQ(vp.origin.y, 50.0 + 0.5 * (300.0 - 150.0));
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 40; ++x) {
      const glm::dvec2 centre = vp.toScreen(glm::dvec2(x, y) + 0.5);
      ASSERT_EQ(vp.pixelAt(centre), glm::ivec2(x, y));
      ASSERT_TRUE(vp.contains(centre));
    }
  }
  EXPECT_FALSE(vp.contains({110.0, 60.0}));  // the letterbox band
}

TEST(Explorer, RegionPickReadsOnlyTheBoundedBox) {
  auto vol = hashVolume({160, 128, 96}, {1.0, 1.0, 2.0}, kLpi);
  vol->setOrigin({10.0, -20.0, 5.0});
  auto counting =
      std::make_shared<CountingSource>(std::make_shared<const lod::InCoreMultiresSource>(vol));
  // A budget of 64^3 bytes: the region side drops from 256 to 64.
  Explorer ex(counting, 64ull * 64 * 64);
  EXPECT_EQ(ex.regionSide(), 64);
  EXPECT_EQ(defaultRegionSide(1ull << 30, 1), 256);
  EXPECT_EQ(defaultRegionSide(1ull << 30, 4), 256);
  EXPECT_EQ(defaultRegionSide(64ull * 64 * 64 * 2 - 1, 2), 48);
  // Picked near a corner: the box is shifted inside the volume.
  const lod::VoxelBox box = ex.regionAt({158, 2, 40});
  EXPECT_EQ(box.begin, glm::ivec3(96, 0, 8));
  EXPECT_EQ(box.end, glm::ivec3(160, 64, 72));
  counting->voxels = 0;
  counting->reads = 0;
  const Volume region = ex.readRegion(box);
  EXPECT_EQ(counting->reads.load(), 1);
  EXPECT_EQ(counting->voxels.load(), 64ull * 64 * 64);
  EXPECT_LT(counting->voxels.load(), vol->voxelCount() / 4);
  EXPECT_EQ(region.dims(), glm::ivec3(64));
  // Native resolution, the same voxels, at the same place in the patient frame.
  for (int z = 0; z < 64; z += 5) {
    for (int y = 0; y < 64; y += 3) {
      for (int x = 0; x < 64; x += 7) {
        ASSERT_EQ(region.valueAt(x, y, z), vol->valueAt(96 + x, y, 8 + z));
      }
    }
  }
  const glm::dvec4 a = region.indexToWorld() * glm::dvec4(3, 4, 5, 1);
  const glm::dvec4 b = vol->indexToWorld() * glm::dvec4(99, 4, 13, 1);
  EXPECT_NEAR(glm::length(glm::dvec3(a - b)), 0.0, 1e-9);
  EXPECT_THROW(ex.readRegion({{150, 0, 0}, {170, 4, 4}}), InputError);
  // A smaller side is kept within 16 .. the budget's side.
  ex.setRegionSide(1000);
  EXPECT_EQ(ex.regionSide(), 64);
  ex.setRegionSide(20);
  EXPECT_EQ(ex.regionAt({80, 64, 48}).size(), glm::ivec3(20));
  // The grid block is one bounded read within the budget too.
  counting->voxels = 0;
  const lod::VoxelBox block = ex.grid().blockBox(ex.grid().point());
  const Volume b8 = ex.readRegion(block);
  EXPECT_EQ(counting->voxels.load(), block.count());
  EXPECT_LE(block.count(), 64ull * 64 * 64);
  EXPECT_EQ(ex.grid().blockCells(ex.grid().point()).size(), 8u);
  EXPECT_EQ(b8.dims(), block.size());
}

// A region marked in a slice view: a drag takes the voxels under the
// rectangle in the slice's plane and the region side across it; a click the
// default cube around the voxel; both clamped to the budget and the volume.
TEST(Explorer, RegionFromASliceDragCoversTheDraggedVoxels) {
  auto vol = hashVolume({200, 160, 120}, {1.0, 1.0, 2.0}, kLpi);
  Explorer ex(std::make_shared<const lod::InCoreMultiresSource>(vol), 64ull * 64 * 64);
  ex.setRegionSide(32);
  const int axial = axisForPlane(kLpi, "axial");
  const SliceGeometry g(vol->dims(), vol->spacing(), kLpi, axial);
  const glm::ivec2 a(30, 40), b(70, 60);
  const lod::VoxelBox box = ex.regionFromSlice(g, a, b, 50);
  const lod::VoxelBox under = g.voxelsUnder(a, b, 50);
  for (int axis = 0; axis < 3; ++axis) {
    if (axis == axial) {
      EXPECT_EQ(box.size()[axis], 32);
      EXPECT_EQ(box.begin[axis], 50 - 16);
    } else {
      EXPECT_EQ(box.begin[axis], under.begin[axis]);
      EXPECT_EQ(box.end[axis], under.end[axis]);
    }
  }
  // Every corner pixel of the rectangle shows a voxel inside the box.
  for (const glm::ivec2 p : {a, b, glm::ivec2(a.x, b.y), glm::ivec2(b.x, a.y)}) {
    const glm::ivec3 v = g.voxelAt(p, 50);
    EXPECT_TRUE(glm::all(glm::greaterThanEqual(v, box.begin)) &&
                glm::all(glm::lessThan(v, box.end)));
  }
  // A drag larger than the budget's side is cut to it; a click is a cube.
  EXPECT_LE(ex.regionFromSlice(g, {0, 0}, {199, 159}, 50).size().x, 64);
  EXPECT_EQ(ex.regionFromSlice(g, a, a, 50).size(), glm::ivec3(32));
}

TEST(Explorer, OverlayLinesSitOnVoxelBoundariesAndCentres) {
  const glm::ivec3 dims(10, 20, 40);
  const glm::dvec3 extent(10.0, 20.0, 80.0);
  // The whole volume's box is the bounding box.
  const auto whole = boxLines({glm::ivec3(0), dims}, dims, extent, glm::vec4(1.0f));
  ASSERT_EQ(whole.size(), 12u);
  for (const auto& l : whole) {
    for (const glm::dvec3& p : {l.a, l.b}) {
      for (int a = 0; a < 3; ++a) EXPECT_DOUBLE_EQ(std::abs(p[a]), 0.5 * extent[a]);
    }
  }
  // The crosshair through voxel (0, 19, 20) runs through its centre.
  const auto cross = crosshairLines({0, 19, 20}, dims, extent, glm::vec4(1.0f));
  ASSERT_EQ(cross.size(), 3u);
  EXPECT_DOUBLE_EQ(cross[0].a.y, (19.5 / 20.0 - 0.5) * 20.0);
  EXPECT_DOUBLE_EQ(cross[0].a.z, (20.5 / 40.0 - 0.5) * 80.0);
  EXPECT_DOUBLE_EQ(cross[0].a.x, -5.0);
  EXPECT_DOUBLE_EQ(cross[0].b.x, 5.0);
  EXPECT_DOUBLE_EQ(cross[2].a.x, (0.5 / 10.0 - 0.5) * 10.0);
}

// A swap between the overview and a native box keeps the view: every pixel's
// ray is the same ray of the patient (shifted by the box's offset in the
// model frame), and swapping back restores the camera.
TEST(Explorer, SwapKeepsEveryPatientPointOnScreen) {
  const glm::ivec3 dims(100, 80, 60);
  const glm::dvec3 spacing(1.0, 1.5, 2.0);
  for (const Projection projection : {Projection::Perspective, Projection::Orthographic}) {
    Camera a;
    a.frame(glm::dvec3(dims) * spacing);
    a.projection = projection;
    a.azimuthDeg = 37.0;
    a.elevationDeg = -20.0;
    a.zoom = 2.3;
    a.target = {5.0, -3.0, 7.0};
    const lod::VoxelBox box{{10, 20, 5}, {60, 70, 45}};
    const Camera b = cameraAcrossSwap(a, std::nullopt, box, dims, spacing);
    const BoxFraming f = boxFraming(box, dims, spacing);
    EXPECT_DOUBLE_EQ(b.radius, 0.5 * glm::length(glm::dvec3(box.size()) * spacing));
    for (const auto& [px, py] : {std::pair{0, 0}, std::pair{63, 17}, std::pair{127, 95}}) {
      const Ray ra = a.pixelRay(px, py, 128, 96), rb = b.pixelRay(px, py, 128, 96);
      EXPECT_NEAR(glm::length(ra.direction - rb.direction), 0.0, 1e-12);
      // Orthographic rays start on the eye plane, which moves along the view
      // axis with the radius: compare the rays as lines.
      const glm::dvec3 d = rb.origin + f.centre - ra.origin;
      EXPECT_NEAR(glm::length(d - glm::dot(d, ra.direction) * ra.direction), 0.0, 1e-9);
      if (projection == Projection::Perspective) {
        EXPECT_NEAR(glm::length(d), 0.0, 1e-9);
      }
    }
    const Camera back = cameraAcrossSwap(b, box, std::nullopt, dims, spacing);
    EXPECT_NEAR(back.zoom, a.zoom, 1e-12);
    EXPECT_NEAR(glm::length(back.target - a.target), 0.0, 1e-12);
  }
}

// The highlighted region shows in the overview: the frame with the box's
// lines differs from the frame without them, and only by line-coloured pixels.
TEST(Explorer, HighlightedRegionIsDrawnInTheOverview) {
  gpu::GlContext& ctx = test::gpuContext();
  auto vol = hashVolume({32, 32, 32}, glm::dvec3(1.0), kRas);
  Viewer v(ctx, gpu::DeviceProfile::find("gles3"));
  v.setVolume(*vol, "hash");
  v.showBoundingBox = v.showAxes = false;
  v.quality = Quality::Full;
  // Lines inside the volume are hidden where it is opaque: a faint volume.
  v.settings().opacityScale = 0.05;
  const int size = 64;
  gpu::Framebuffer fb = gpu::Framebuffer::create(ctx.ledger(), "explore test", size, size);
  auto frame = [&] {
    v.render(size, size, fb.id());
    Image img(size, size);
    fb.readRgba8(img.rgba().data());
    return img;
  };
  const Image plain = frame();
  v.extraLines = boxLines({{4, 4, 4}, {20, 20, 20}}, vol->dims(), vol->extent(),
                          glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));
  const Image marked = frame();
  int redder = 0;
  for (int i = 0; i < size * size; ++i) {
    const std::uint8_t* p = &plain.rgba()[static_cast<std::size_t>(i) * 4];
    const std::uint8_t* m = &marked.rgba()[static_cast<std::size_t>(i) * 4];
    if (m[0] > p[0] + 20 && m[1] <= p[1] + 2) ++redder;
  }
  EXPECT_GT(redder, 20);
}

}  // namespace
}  // namespace tessera::viewer
