// The CPU reference renders FCC volumes through BoxSplineReconstruction.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

#include "lattice/Blobs.h"
#include "support/TestCameras.h"
#include "tessera/core/Camera.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/lattice/BoxSplineReconstruction.h"
#include "tessera/lattice/FccResampling.h"
#include "tessera/lattice/MarschnerLobb.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"

using namespace tessera;
using namespace tessera::lattice;

namespace {

constexpr int kImage = 64;

// The blobs in [0,1] as floats.
Volume blobs(glm::ivec3 dims) {
  Volume v = test::blobs(dims, ScalarType::F32);
  v.setWindow({0.0, 1.0});
  return v;
}

Camera obliqueCamera(const Volume& v) {
  return test::orbitCamera(v, 30, 20);
}

}  // namespace

TEST(BoxSplineReconstruction, IsTheSplineInTextureSpaceWithItsExactGradient) {
  const Volume source = blobs({16, 14, 12});
  const FccVolume fcc = resampleToFcc(source);
  const BoxSplineReconstruction field(fcc);
  const FccBoxSpline spline(fcc);
  EXPECT_EQ(field.dims(), fcc.gridDims());
  EXPECT_EQ(field.supportVoxels(), 2);
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> d(0.05, 0.95);
  for (int i = 0; i < 100; ++i) {
    const glm::dvec3 p(d(rng), d(rng), d(rng));
    const glm::dvec3 u = p * glm::dvec3(fcc.gridDims()) - 0.5;
    EXPECT_DOUBLE_EQ(field.value(p), spline.value(u));
    // Against central differences through value() (the seam's default).
    const glm::dvec3 g = field.gradient(p);
    const glm::dvec3 h = 1e-5 / glm::dvec3(fcc.gridDims());
    for (int a = 0; a < 3; ++a) {
      glm::dvec3 e(0.0);
      e[a] = h[a];
      const double fd = (field.value(p + e) - field.value(p - e)) / (2 * h[a]);
      EXPECT_NEAR(g[a], fd, 1e-5 * (1.0 + std::abs(fd)));
    }
  }
}

// An FCC resampling of a smooth volume renders like the trilinear reference
// of the original (the two reconstructions differ slightly: neither is exact).
TEST(BoxSplineReconstruction, FccResamplingOfASmoothVolumeRendersLikeTheCartesianReference) {
  const Volume source = blobs(glm::ivec3(48));
  const Camera cam = obliqueCamera(source);
  const RenderSettings s;
  for (const auto& [tfName, tf] :
       {std::pair{"soft", marschnerLobbSoftTf()}, std::pair{"iso", marschnerLobbIsoTf()}}) {
    const Image cartesian = renderReference(source, tf, cam, s, kImage, kImage);
    for (const FccDensity density : {FccDensity::Same, FccDensity::Half}) {
      FccResampleOptions options;
      options.density = density;
      const FccVolume fcc = resampleToFcc(source, options);
      const Image img =
          renderReference(fcc.box(), BoxSplineReconstruction(fcc), tf, cam, s, kImage, kImage);
      const double db = psnr(img, cartesian);
      std::printf(
          "[measured] blobs 48^3 (%s TF): FCC %s box spline vs Cartesian trilinear "
          "reference: %.1f dB\n",
          tfName, std::string(fccDensityName(density)).c_str(), db);
      EXPECT_GT(db, 35.0);
    }
  }
}

// Image-level version of the RMS table: against the reference of the
// analytic signal, FCC + box spline (same sample count) is closer than
// Cartesian + trilinear.
TEST(BoxSplineReconstruction, MarschnerLobbOnFccRendersCloserToTheSignalThanTrilinear) {
  for (const int n : {41, 64}) {
    const Volume cartesian = makeMarschnerLobb(glm::ivec3(n));
    const Camera cam = obliqueCamera(cartesian);
    const RenderSettings s;
    const FccVolume fcc = makeMarschnerLobbFcc(cartesian, FccDensity::Same);
    for (const auto& [tfName, tf] :
         {std::pair{"soft", marschnerLobbSoftTf()}, std::pair{"iso", marschnerLobbIsoTf()}}) {
      const Image truth = renderReference(cartesian, MarschnerLobbSignal(cartesian.dims()), tf, cam,
                                          s, kImage, kImage);
      const double trilinear = psnr(renderReference(cartesian, tf, cam, s, kImage, kImage), truth);
      const double box =
          psnr(renderReference(fcc.box(), BoxSplineReconstruction(fcc), tf, cam, s, kImage, kImage),
               truth);
      std::printf(
          "[measured] Marschner-Lobb %d^3 (%s TF) vs the analytic signal's image: Cartesian "
          "trilinear %.1f dB, FCC same box spline %.1f dB\n",
          n, tfName, trilinear, box);
      EXPECT_GT(box, trilinear);
    }
  }
}

// Real data (the FCC acceptance, CPU side): the ch2 MRI head on the FCC
// lattice at half and same density, rendered through the box spline, against
// the trilinear reference of the original. Skipped without mricron-data.
TEST(BoxSplineReconstruction, Ch2OnFccRendersLikeTheOriginal) {
  const char* path = "/usr/share/mricron/templates/ch2.nii.gz";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not installed (mricron-data)";
  const Volume ch2 = readVolume(path);
  const TransferFunction tf = TransferFunction::preset("mr-default");
  Camera cam = test::orbitCamera(ch2, 30, 15);
  const RenderSettings s;
  const Image original = renderReference(ch2, tf, cam, s, kImage, kImage);
  for (const FccDensity density : {FccDensity::Half, FccDensity::Same}) {
    FccResampleOptions options;
    options.density = density;
    FccResampleStats stats;
    const auto start = std::chrono::steady_clock::now();
    const FccVolume fcc = resampleToFcc(ch2, options, &stats);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double db =
        psnr(renderReference(fcc.box(), BoxSplineReconstruction(fcc), tf, cam, s, kImage, kImage),
             original);
    std::printf(
        "[measured] ch2 %s (resampled in %.2f s, %llu saturated): box spline vs the "
        "original's trilinear reference %.1f dB\n",
        fcc.summary(fccDensityName(density)).c_str(), seconds,
        static_cast<unsigned long long>(stats.saturated), db);
    EXPECT_GT(db, 30.0);
  }
}
