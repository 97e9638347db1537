// Label volumes (issue 16, item 3): nearest-neighbour sampling and a
// categorical table, on every technique and layout; label table files.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <set>
#include <vector>

#include "support/GpuTestContext.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/layout/MosaicLayout.h"
#include "tessera/layout/PackedMosaicLayout.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/LabelTable.h"
#include "tessera/render/Raycaster.h"
#include "tessera/render/Slice2DRenderer.h"
#include "tessera/render/Slice3DRenderer.h"

using namespace tessera;

namespace {

glm::ivec3 rgb8(glm::dvec3 c) {
  return glm::ivec3(glm::round(c * 255.0));
}

// Every technique on every layout of a context, rendering `v` with `tf`.
template <class Check>
void forEveryPath(gpu::ApiLevel api, const Volume& v, const TransferFunction& tf, const Camera& cam,
                  const RenderSettings& s, int size, Check check) {
  gpu::GlContext::Options o;
  o.api = api;
  auto owned = api == gpu::ApiLevel::Gles2 ? gpu::GlContext::createHeadless(o) : nullptr;
  gpu::GlContext& c = owned ? *owned : test::gpuContext();
  {
    const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
    gpu::DeviceLimits packedLimits = limits;
    packedLimits.max2DTextureSize = 64;
    std::vector<std::unique_ptr<layout::Layout>> layouts;
    if (api == gpu::ApiLevel::Gles3) {
      layouts.push_back(layout::Texture3DLayout::create(v, limits, c.ledger()));
    }
    layouts.push_back(layout::MosaicLayout::create(v, limits, c.ledger()));
    layouts.push_back(layout::PackedMosaicLayout::create(v, packedLimits, c.ledger(), 6));
    const std::string a = api == gpu::ApiLevel::Gles2 ? "gles2 " : "gles3 ";
    for (const auto& l : layouts) {
      render::Raycaster caster(c, v, *l);
      caster.setLutSize(256);
      caster.setTransferFunction(tf);
      check(caster.render(cam, s, size, size), a + "raycast " + l->name());
      render::Slice3DRenderer slicer(c, v, *l);
      slicer.setTransferFunction(tf);
      check(slicer.render(cam, s, size, size), a + "slice3d " + l->name());
    }
    render::Slice2DRenderer slicer2d(c, v, {});
    slicer2d.setTransferFunction(tf);
    check(slicer2d.render(cam, s, size, size), a + "slice2d");
  }
  owned.reset();
  test::gpuContext();
}

RenderSettings labelSettings() {
  RenderSettings s;
  s.nearest = true;
  s.ertThreshold = 1.0;  // slicing cannot stop early
  return s;
}

}  // namespace

// 12x10 columns of distinct labels (three identical slices), seen from above
// through opaque labels: at every voxel centre the pixel is that voxel's
// label colour, exactly (no blur across labels), for every path and the reference.
TEST(Labels, EveryVoxelsColourAppearsAtItsCentre) {
  Volume v = Volume::allocate({12, 10, 3}, ScalarType::U8, "labels");
  for (int z = 0; z < 3; ++z)
    for (int y = 0; y < 10; ++y)
      for (int x = 0; x < 12; ++x) v.setValueAtIndex(v.index(x, y, z), 1 + x + 12 * y);
  v.invalidateRange();
  render::prepareLabelVolume(v);
  const render::LabelTable table = render::LabelTable::defaultFor(v);
  ASSERT_EQ(table.labels.size(), 120u);
  const TransferFunction tf = table.toTransferFunction();
  Camera cam;
  cam.projection = Projection::Orthographic;
  cam.elevationDeg = 90;
  cam.frame(v.extent());
  const RenderSettings s = labelSettings();
  auto check = [&](const Image& img, const std::string& what) {
    std::set<int> covered;
    int worst = 0;
    for (int py = 0; py < img.height(); ++py) {
      for (int px = 0; px < img.width(); ++px) {
        const Ray ray = cam.pixelRay(px, py, img.width(), img.height());
        const double t = (v.extent().z / 2 - ray.origin.z) / ray.direction.z;
        const glm::dvec3 i =
            ((ray.origin + t * ray.direction) / v.extent() + 0.5) * glm::dvec3(v.dims()) - 0.5;
        const glm::dvec3 r = glm::round(i);
        if (std::abs(i.x - r.x) > 0.3 || std::abs(i.y - r.y) > 0.3 || r.x < 0 || r.y < 0 ||
            r.x > 11 || r.y > 9) {
          continue;
        }
        const int label = 1 + static_cast<int>(r.x) + 12 * static_cast<int>(r.y);
        covered.insert(label);
        const glm::ivec3 want = rgb8(table.labels.at(label).color);
        const std::uint8_t* p = img.pixel(px, py);
        for (int ch = 0; ch < 3; ++ch) worst = std::max(worst, std::abs(p[ch] - want[ch]));
      }
    }
    std::printf("  [measured] labels %-28s %zu voxel centres, worst %d/255\n", what.c_str(),
                covered.size(), worst);
    EXPECT_EQ(covered.size(), 120u) << what;
    EXPECT_LE(worst, 1) << what;
  };
  check(renderReference(v, tf, cam, s, 120, 120), "reference");
  for (gpu::ApiLevel api : {gpu::ApiLevel::Gles3, gpu::ApiLevel::Gles2}) {
    forEveryPath(api, v, tf, cam, s, 120, check);
  }
}

// Random labels in 3D, an oblique perspective view, opaque labels: every
// pixel is the background or a colour of the table — nothing in between.
TEST(Labels, NoColourOutsideTheTableAppears) {
  Volume v = Volume::allocate({20, 18, 16}, ScalarType::U8, "labels");
  std::mt19937 rng(7);
  for (std::size_t i = 0; i < static_cast<std::size_t>(v.voxelCount()); ++i) {
    v.setValueAtIndex(i, static_cast<double>(rng() % 31));  // 0: background
  }
  v.invalidateRange();
  render::prepareLabelVolume(v);
  const render::LabelTable table = render::LabelTable::defaultFor(v);
  const TransferFunction tf = table.toTransferFunction();
  std::vector<glm::ivec3> allowed{glm::ivec3(0)};  // the black background
  for (const auto& [value, label] : table.labels) allowed.push_back(rgb8(label.color));
  Camera cam;
  cam.azimuthDeg = 33;
  cam.elevationDeg = 21;
  cam.frame(v.extent());
  const RenderSettings s = labelSettings();
  auto check = [&](const Image& img, const std::string& what) {
    int outside = 0, drawn = 0;
    for (int py = 0; py < img.height(); ++py) {
      for (int px = 0; px < img.width(); ++px) {
        const std::uint8_t* p = img.pixel(px, py);
        const glm::ivec3 c(p[0], p[1], p[2]);
        bool found = false;
        for (const glm::ivec3& a : allowed) {
          const glm::ivec3 d = glm::abs(c - a);
          found = found || (d.x <= 1 && d.y <= 1 && d.z <= 1);
        }
        outside += found ? 0 : 1;
        drawn += c != glm::ivec3(0) ? 1 : 0;
      }
    }
    std::printf("  [measured] labels %-28s %d label pixels, %d not in the table\n", what.c_str(),
                drawn, outside);
    EXPECT_GT(drawn, 1000) << what;
    EXPECT_EQ(outside, 0) << what;
  };
  check(renderReference(v, tf, cam, s, 80, 80), "reference");
  for (gpu::ApiLevel api : {gpu::ApiLevel::Gles3, gpu::ApiLevel::Gles2}) {
    forEveryPath(api, v, tf, cam, s, 80, check);
  }
}
