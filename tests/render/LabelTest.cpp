// Label volumes: nearest-neighbour sampling and a
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
#include "support/LabelPalette.h"
#include "support/TestCameras.h"
#include "support/TestLayouts.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/LabelTable.h"
#include "tessera/render/Raycaster.h"
#include "tessera/render/Slice2DRenderer.h"
#include "tessera/render/Slice3DRenderer.h"

using namespace tessera;

namespace {

using test::rgb8;

// Every technique on every layout of a context, rendering `v` with `tf`.
template <class Check>
void forEveryPath(gpu::ApiLevel api, const Volume& v, const TransferFunction& tf, const Camera& cam,
                  const RenderSettings& s, int size, Check check) {
  test::ApiContext context(api);
  gpu::GlContext& c = context.get();
  const auto layouts = test::gridLayouts(c, api, v, 64);
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
  const Camera cam = test::topDownOrthographic(v.extent());
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
  Camera cam = test::orbitCamera(v.extent(), 33, 21);
  const RenderSettings s = labelSettings();
  auto check = [&](const Image& img, const std::string& what) {
    const auto [drawn, outside] = test::countAgainstPalette(img, table);
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

TEST(LabelTable, ReadsJsonItkSnapFreeSurferAndMricronText) {
  const render::LabelTable json = render::LabelTable::fromJson(
      R"({"labels": [{"value": 3, "name": "a", "color": [1, 0, 0.5], "opacity": 0.5},
                     {"value": 7, "visible": false}]})",
      "t.json");
  ASSERT_EQ(json.labels.size(), 2u);
  EXPECT_EQ(json.labels.at(3).color, glm::dvec3(1.0, 0.0, 0.5));
  EXPECT_EQ(json.labels.at(3).opacity, 0.5);
  EXPECT_FALSE(json.labels.at(7).visible);
  const render::LabelTable itk = render::LabelTable::fromText(
      "# ITK-SnAP Label Description File\n"
      "    0     0    0    0        0  0  0    \"Clear Label\"\n"
      "    1   255    0    0        1  1  1    \"Left hippocampus\"\n"
      "    2     0  255    0     0.25  0  1    \"Right\"\n",
      "t.txt");
  ASSERT_EQ(itk.labels.size(), 2u);  // 0 is the background
  EXPECT_EQ(itk.labels.at(1).name, "Left hippocampus");
  EXPECT_EQ(itk.labels.at(1).color, glm::dvec3(1.0, 0.0, 0.0));
  EXPECT_EQ(itk.labels.at(2).opacity, 0.25);
  EXPECT_FALSE(itk.labels.at(2).visible);
  const render::LabelTable fs =
      render::LabelTable::fromText("0 Unknown 0 0 0 0\n17 Left-Hippocampus 220 216 20 0\n", "lut");
  EXPECT_EQ(fs.labels.at(17).color, glm::dvec3(220, 216, 20) / 255.0);
  const render::LabelTable mricron =
      render::LabelTable::fromText("1 Precentral_L 2001\n2 Precentral_R 2002\n", "aal.nii.txt");
  EXPECT_EQ(mricron.labels.at(2).name, "Precentral_R");
  EXPECT_EQ(mricron.labels.at(2).color, render::LabelTable::paletteColor(2));
  // The table as a TF: each label's colour and opacity exactly at value / 255, 0 transparent,
  // hidden and unnamed labels transparent.
  const TransferFunction tf = json.toTransferFunction();
  EXPECT_EQ(tf.color(3 / 255.0), glm::dvec3(1.0, 0.0, 0.5));
  EXPECT_EQ(tf.opacity(3 / 255.0), 0.5);
  EXPECT_EQ(tf.opacity(7 / 255.0), 0.0);
  EXPECT_EQ(tf.opacity(4 / 255.0), 0.0);
  EXPECT_EQ(tf.opacity(0.0), 0.0);
}

TEST(LabelTable, BadFilesSayWhatAndWhere) {
  auto message = [](auto parse) {
    try {
      parse();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([] {
              render::LabelTable::fromText("1 255 0 0 1 1 1 \"a\"\nx y\n", "f.txt");
            }).find("f.txt:2"),
            std::string::npos);
  EXPECT_NE(message([] { render::LabelTable::fromText("300 big\n", "f.txt"); }).find("0..255"),
            std::string::npos);
  EXPECT_NE(message([] {
              render::LabelTable::fromText("1 300 0 0 1 1 1 \"a\"\n", "f.txt");
            }).find("colour channel"),
            std::string::npos);
  EXPECT_NE(
      message([] { render::LabelTable::fromText("# only comments\n", "f.txt"); }).find("no labels"),
      std::string::npos);
  EXPECT_NE(message([] {
              render::LabelTable::fromJson("{\"labels\": [{\"name\": 1}]}", "f.json");
            }).find("labels[0]"),
            std::string::npos);
  EXPECT_NE(message([] { render::LabelTable::fromJson("not json", "f.json"); }).find("not JSON"),
            std::string::npos);
  Volume f = Volume::allocate({2, 2, 2}, ScalarType::F32, "f");
  f.setValueAtIndex(0, 1.5);
  f.invalidateRange();
  EXPECT_NE(message([&] { render::prepareLabelVolume(f); }).find("non-integer"), std::string::npos);
}

TEST(LabelTable, ReadsMricronsAalTable) {
  const char* path = "/usr/share/mricron/templates/aal.nii.txt";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "mricron-data not installed";
  const render::LabelTable t = render::LabelTable::load(path);
  EXPECT_EQ(t.labels.size(), 116u);
  EXPECT_EQ(t.labels.at(1).name, "Precentral_L");
}
