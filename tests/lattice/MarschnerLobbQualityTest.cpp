// Marschner-Lobb on the FCC lattice with the box spline against the
// Cartesian grid with trilinear interpolation: the reconstructed signal vs
// the analytic one, along the reference's rays and at random points.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "support/TestCameras.h"
#include "tessera/core/Camera.h"
#include "tessera/io/Procedural.h"
#include "tessera/lattice/BoxSplineReconstruction.h"
#include "tessera/lattice/FccResampling.h"
#include "tessera/lattice/MarschnerLobb.h"
#include "tessera/reference/Reconstruction.h"

using namespace tessera;
using namespace tessera::lattice;

namespace {

std::vector<glm::dvec3> randomSamples(int n) {
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> d(0.0, 1.0);
  std::vector<glm::dvec3> out;
  for (int i = 0; i < n; ++i) out.push_back({d(rng), d(rng), d(rng)});
  return out;
}

struct Row {
  double rays, random;
};

// RMS errors of fields over the box of a makeMarschnerLobb() volume, printed
// as table rows.
class Quality {
 public:
  explicit Quality(const Volume& cartesian)
      : dims_(cartesian.dims()), random_(randomSamples(40000)) {
    Camera camera = test::orbitCamera(cartesian, 30, 20);
    rays_ = raySamplePositions(cartesian, camera, 48);
  }
  Row row(const std::string& name, std::uint64_t samples, const Reconstruction& field) const {
    const Row r{marschnerLobbRms(field, rays_, dims_), marschnerLobbRms(field, random_, dims_)};
    std::printf("[measured] %-44s %8llu %10.5f %10.5f\n", name.c_str(),
                static_cast<unsigned long long>(samples), r.rays, r.random);
    return r;
  }

 private:
  glm::ivec3 dims_;
  std::vector<glm::dvec3> rays_, random_;
};

}  // namespace

// The FCC acceptance table: at the same sample count the box spline on
// FCC beats trilinear on the Cartesian grid, once its samples are
// quasi-interpolated (Kim 2013); raw samples as coefficients blur too much.
TEST(MarschnerLobbQuality, FccBoxSplineBeatsCartesianTrilinearAtTheSameSampleCount) {
  std::printf(
      "[measured] Marschner-Lobb (fM = 6, alpha = 0.25): RMS error of the reconstructed "
      "signal, values in [0,1]\n[measured] %-44s %8s %10s %10s\n",
      "lattice, reconstruction", "samples", "along rays", "random pts");
  for (const int n : {41, 64}) {
    const Volume cartesian = makeMarschnerLobb(glm::ivec3(n));
    const Quality q(cartesian);
    const Row trilinear = q.row("Cartesian " + std::to_string(n) + "^3, trilinear",
                                cartesian.voxelCount(), TrilinearReconstruction(cartesian));
    for (const FccDensity density : {FccDensity::Same, FccDensity::Half}) {
      const FccVolume raw = makeMarschnerLobbFcc(cartesian, density, false);
      const FccVolume qi = makeMarschnerLobbFcc(cartesian, density);
      const std::string label = "FCC " + std::string(fccDensityName(density)) + " (" +
                                std::to_string(raw.gridDims().x) + "^3 grid), box spline";
      q.row(label + ", samples", raw.pointCount(), BoxSplineReconstruction(raw));
      const Row best = q.row(label + ", QI", qi.pointCount(), BoxSplineReconstruction(qi));
      if (density == FccDensity::Same) {
        EXPECT_LT(best.rays, trilinear.rays) << n;
        EXPECT_LT(best.random, trilinear.random) << n;
      }
    }
  }
}

// How much of that survives resampling a Cartesian volume onto the lattice
// (same density, quasi-interpolated) depends on the interpolant: the cubic
// B-spline (order 4) loses little against sampling the signal directly.
TEST(MarschnerLobbQuality, CubicBSplineResamplingKeepsTheLatticesAdvantage) {
  const Volume cartesian = makeMarschnerLobb(glm::ivec3(64));
  const Quality q(cartesian);
  std::printf("[measured] Marschner-Lobb 64^3 resampled onto FCC (same density, QI)\n");
  const Row trilinear = q.row("Cartesian 64^3, trilinear", cartesian.voxelCount(),
                              TrilinearReconstruction(cartesian));
  const FccVolume direct = makeMarschnerLobbFcc(cartesian, FccDensity::Same);
  const Row ideal =
      q.row("FCC sampled directly", direct.pointCount(), BoxSplineReconstruction(direct));
  std::vector<Row> resampled;
  for (const auto& [name, kind] :
       {std::pair{"trilinear", CartesianInterpolant::Trilinear},
        std::pair{"Catmull-Rom", CartesianInterpolant::CatmullRom},
        std::pair{"cubic B-spline", CartesianInterpolant::CubicBSpline}}) {
    FccResampleOptions options;
    options.interpolant = kind;
    const FccVolume fcc = resampleToFcc(cartesian, options);
    resampled.push_back(q.row(std::string("FCC resampled, ") + name, fcc.pointCount(),
                              BoxSplineReconstruction(fcc)));
  }
  EXPECT_LT(resampled[2].random, resampled[1].random);
  EXPECT_LT(resampled[1].random, resampled[0].random);
  EXPECT_LT(resampled[2].random, trilinear.random);
  EXPECT_LT(resampled[2].random, 1.5 * ideal.random);
}
