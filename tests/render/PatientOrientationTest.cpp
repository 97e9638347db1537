// The same anatomy renders the same image whatever its storage order
// (patient geometry): a marked phantom stored RAS, mirrored (LAS), LPS, sagittal and
// coronal stacks and a scrambled order, each with the direction cosines that
// say so, against the RAS render from three views. Storage changes are exact
// permutations of voxels, so every technique must agree with itself to far
// better than the 40 dB image threshold.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "support/GpuTestContext.h"
#include "support/TestCameras.h"
#include "support/TestTransferFunctions.h"
#include "tessera/core/Camera.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/Raycaster.h"
#include "tessera/render/Slice2DRenderer.h"
#include "tessera/render/Slice3DRenderer.h"

using namespace tessera;

namespace {

// How a RAS volume is stored: index axis a runs along world axis
// `worldAxis[a]`, towards its negative end when `reversed[a]`.
struct Storage {
  const char* code;  // nibabel-style orientation code of the result
  std::array<int, 3> worldAxis;
  std::array<bool, 3> reversed;
};

const std::array<Storage, 6> kStorages{{
    {"RAS", {0, 1, 2}, {false, false, false}},
    {"LAS", {0, 1, 2}, {true, false, false}},
    {"LPS", {0, 1, 2}, {true, true, false}},
    {"PIL", {1, 2, 0}, {true, true, true}},    // sagittal slices, DICOM-like
    {"LIP", {0, 2, 1}, {true, true, true}},    // coronal slices
    {"SRP", {2, 0, 1}, {false, false, true}},  // scrambled
}};

// A head-sized phantom with a bright block on the patient's right-anterior
// side, so any mirror or turn shows.
Volume markedPhantom(bool marker = true) {
  Volume v = makeSheppLogan({40, 48, 36});
  v.setSpacing({1.0, 0.9, 1.2});
  v.setOrigin({-20.0, -21.0, -18.0});
  const glm::ivec3 d = v.dims();
  const double bright = v.window().max;
  v.setWindow(v.window());  // the marker must not change the value window
  if (!marker) return v;
  for (int z = d.z / 2; z < d.z / 2 + 8; ++z) {
    for (int y = d.y - 12; y < d.y - 4; ++y) {
      for (int x = d.x - 12; x < d.x - 5; ++x) v.setValueAtIndex(v.index(x, y, z), bright);
    }
  }
  return v;
}

Volume store(const Volume& ras, const Storage& s) {
  glm::ivec3 dims;
  glm::dvec3 spacing;
  glm::dmat3 direction(0.0);
  for (int a = 0; a < 3; ++a) {
    const int w = s.worldAxis[static_cast<std::size_t>(a)];
    dims[a] = ras.dims()[w];
    spacing[a] = ras.spacing()[w];
    direction[a][w] = s.reversed[static_cast<std::size_t>(a)] ? -1.0 : 1.0;
  }
  Volume out = Volume::allocate(dims, ras.type(), s.code);
  out.setSpacing(spacing);
  out.setDirection(direction);
  auto rasIndex = [&](glm::ivec3 n) {
    glm::ivec3 r;
    for (int a = 0; a < 3; ++a) {
      const int w = s.worldAxis[static_cast<std::size_t>(a)];
      r[w] = s.reversed[static_cast<std::size_t>(a)] ? dims[a] - 1 - n[a] : n[a];
    }
    return r;
  };
  out.setOrigin(ras.worldOf(glm::dvec3(rasIndex({0, 0, 0}))));
  for (int z = 0; z < dims.z; ++z) {
    for (int y = 0; y < dims.y; ++y) {
      for (int x = 0; x < dims.x; ++x) {
        const glm::ivec3 r = rasIndex({x, y, z});
        out.setValueAtIndex(out.index(x, y, z), ras.valueAt(r.x, r.y, r.z));
      }
    }
  }
  out.setWindow(ras.window());
  return out;
}

using test::visibleTf;

struct View {
  double azimuth, elevation;
};
constexpr std::array<View, 3> kViews{{{0.0, 0.0}, {90.0, 0.0}, {35.0, 40.0}}};

Camera cameraFor(const Volume& v, View view) {
  return test::orbitCamera(v, view.azimuth, view.elevation);
}

RenderSettings settings() {
  RenderSettings s;
  s.stepVoxels = 0.5;
  s.ertThreshold = 1.0;  // the slicers cannot stop early; keep all paths alike
  return s;
}

constexpr int kSize = 96;

enum class Path { Reference, Raycast, Slice3D, Slice2D };
const char* name(Path p) {
  switch (p) {
    case Path::Reference:
      return "reference";
    case Path::Raycast:
      return "raycast";
    case Path::Slice3D:
      return "slice3d";
    case Path::Slice2D:
      return "slice2d";
  }
  return "?";
}

Image renderWith(Path path, const Volume& v, View view) {
  const TransferFunction tf = visibleTf();
  const Camera cam = cameraFor(v, view);
  const RenderSettings s = settings();
  if (path == Path::Reference) return renderReference(v, tf, cam, s, kSize, kSize);
  gpu::GlContext& c = test::gpuContext();
  if (path == Path::Slice2D) {
    render::Slice2DRenderer slicer(c, v, render::Slice2DOptions{});
    slicer.setTransferFunction(tf);
    return slicer.render(cam, s, kSize, kSize);
  }
  auto layout = layout::Texture3DLayout::create(v, gpu::DeviceLimits::of(c.caps()), c.ledger());
  if (path == Path::Slice3D) {
    render::Slice3DRenderer slicer(c, v, *layout);
    slicer.setTransferFunction(tf);
    return slicer.render(cam, s, kSize, kSize);
  }
  render::Raycaster caster(c, v, *layout);
  caster.setTransferFunction(tf);
  return caster.render(cam, s, kSize, kSize);
}

// Fraction of pixels that are not background: guards against comparing two
// empty images.
double litFraction(const Image& img) {
  int lit = 0;
  for (int y = 0; y < img.height(); ++y) {
    for (int x = 0; x < img.width(); ++x) {
      const auto p = img.pixel(x, y);
      lit += p[0] + p[1] + p[2] > 30;
    }
  }
  return static_cast<double>(lit) / (img.width() * img.height());
}

}  // namespace

TEST(PatientOrientation, StoragesCarryTheOrientationCodeOfTheirDirections) {
  const Volume ras = markedPhantom();
  for (const Storage& s : kStorages) {
    EXPECT_EQ(orientationOf(store(ras, s).direction()).code, s.code);
  }
}

TEST(PatientOrientation, StoredVoxelsSitAtTheSameWorldPositions) {
  const Volume ras = markedPhantom();
  for (const Storage& s : kStorages) {
    const Volume v = store(ras, s);
    EXPECT_NEAR(glm::length(v.worldCentre() - ras.worldCentre()), 0.0, 1e-9) << s.code;
    // Every corner voxel of the stored copy holds the RAS value at its world point.
    for (int corner = 0; corner < 8; ++corner) {
      const glm::ivec3 n((corner & 1) ? v.dims().x - 1 : 0, (corner & 2) ? v.dims().y - 1 : 0,
                         (corner & 4) ? v.dims().z - 1 : 0);
      const glm::dvec3 world = v.worldOf(glm::dvec3(n));
      const glm::dvec3 r = glm::inverse(glm::dmat3(ras.indexToWorld())) * (world - ras.origin());
      const glm::ivec3 ri(glm::round(r));
      EXPECT_NEAR(glm::length(r - glm::dvec3(ri)), 0.0, 1e-9) << s.code;
      EXPECT_EQ(v.valueAt(n.x, n.y, n.z), ras.valueAt(ri.x, ri.y, ri.z)) << s.code;
    }
  }
}

// One test per path so a failure names the technique.
class EveryStorage : public ::testing::TestWithParam<Path> {};

TEST_P(EveryStorage, RendersTheRasImageFromEveryView) {
  const Path path = GetParam();
  const Volume ras = markedPhantom();
  for (const View view : kViews) {
    const Image expected = renderWith(path, ras, view);
    ASSERT_GT(litFraction(expected), 0.05) << "RAS render is (nearly) empty";
    for (const Storage& s : kStorages) {
      const Image got = renderWith(path, store(ras, s), view);
      const double db = psnr(got, expected);
      std::printf("  [measured] %s %s az %g el %g: %.2f dB vs RAS\n", name(path), s.code,
                  view.azimuth, view.elevation, db);
      EXPECT_GE(db, 50.0) << name(path) << " " << s.code << " az " << view.azimuth;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Paths, EveryStorage,
                         ::testing::Values(Path::Reference, Path::Raycast, Path::Slice3D,
                                           Path::Slice2D),
                         [](const auto& param) { return std::string(name(param.param)); });

// Azimuth 0 looks at the face: the marker on the patient's right-anterior
// side appears on the left half of the image (the patient faces the viewer)
// and on the right half from behind, from every storage order.
TEST(PatientOrientation, FrontViewShowsThePatientsRightOnTheImageLeft) {
  const Volume marked = markedPhantom(true);
  const Volume plain = markedPhantom(false);
  for (const Storage& s : kStorages) {
    for (const double azimuth : {0.0, 180.0}) {
      const Image a = renderWith(Path::Reference, store(marked, s), {azimuth, 0.0});
      const Image b = renderWith(Path::Reference, store(plain, s), {azimuth, 0.0});
      // Centroid of where the marker changed the image.
      double sum = 0.0, sumX = 0.0;
      for (int y = 0; y < a.height(); ++y) {
        for (int x = 0; x < a.width(); ++x) {
          double d = 0.0;
          for (int c = 0; c < 3; ++c) d += std::abs(a.pixel(x, y)[c] - b.pixel(x, y)[c]);
          sum += d;
          sumX += d * (x + 0.5);
        }
      }
      ASSERT_GT(sum, 0.0) << s.code << ": the marker is not visible";
      const double centroid = sumX / sum / a.width();
      std::printf("  [measured] %s az %g: marker centroid at %.2f of the width\n", s.code, azimuth,
                  centroid);
      if (azimuth == 0.0) {
        EXPECT_LT(centroid, 0.45) << s.code;
      } else {
        EXPECT_GT(centroid, 0.55) << s.code;
      }
    }
  }
}
