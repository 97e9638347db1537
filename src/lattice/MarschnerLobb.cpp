#include "tessera/lattice/MarschnerLobb.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "tessera/lattice/FccResampling.h"

namespace tessera::lattice {

double marschnerLobb(glm::dvec3 x) {
  constexpr double kFm = 6.0;
  constexpr double kAlpha = 0.25;
  constexpr double pi = std::numbers::pi;
  const double r = std::sqrt(x.x * x.x + x.y * x.y);
  const double rho = std::cos(2.0 * pi * kFm * std::cos(pi * r / 2.0));
  return (1.0 - std::sin(pi * x.z / 2.0) + kAlpha * (1.0 + rho)) / (2.0 * (1.0 + kAlpha));
}

glm::dvec3 marschnerLobbCoordinate(glm::ivec3 dims, glm::dvec3 p) {
  glm::dvec3 x;
  for (int a = 0; a < 3; ++a) {
    const double index = p[a] * dims[a] - 0.5;
    x[a] = dims[a] > 1 ? -1.0 + 2.0 * index / (dims[a] - 1) : 0.0;
  }
  return x;
}

FccVolume makeMarschnerLobbFcc(const Volume& cartesian, FccDensity density,
                               bool quasiInterpolated) {
  const glm::ivec3 dims = cartesian.dims();
  return sampleOnFcc(
      cartesian, density,
      [dims](glm::dvec3 p) { return marschnerLobb(marschnerLobbCoordinate(dims, p)); },
      quasiInterpolated);
}

std::vector<glm::dvec3> raySamplePositions(const Volume& box, const Camera& camera, int size) {
  const glm::dvec3 extent = box.extent();
  const double ds = 0.5 * std::min({box.spacing().x, box.spacing().y, box.spacing().z});
  std::vector<glm::dvec3> out;
  for (int py = 0; py < size; ++py) {
    for (int px = 0; px < size; ++px) {
      const Ray ray = camera.pixelRay(px, py, size, size);
      const glm::dvec3 to = ray.origin / extent + 0.5, td = ray.direction / extent;
      double tNear = -1e300, tFar = 1e300;
      for (int a = 0; a < 3; ++a) {
        if (td[a] == 0.0) continue;
        const double t0 = -to[a] / td[a], t1 = (1.0 - to[a]) / td[a];
        tNear = std::max(tNear, std::min(t0, t1));
        tFar = std::min(tFar, std::max(t0, t1));
      }
      for (double t = std::max(tNear, 0.0) + 0.5 * ds; t < tFar; t += ds) {
        out.push_back(to + t * td);
      }
    }
  }
  return out;
}

double marschnerLobbRms(const Reconstruction& field, const std::vector<glm::dvec3>& at,
                        glm::ivec3 dims) {
  double sum = 0.0;
  for (const glm::dvec3& p : at) {
    const double e = field.value(p) - marschnerLobb(marschnerLobbCoordinate(dims, p));
    sum += e * e;
  }
  return std::sqrt(sum / static_cast<double>(at.size()));
}

TransferFunction marschnerLobbSoftTf() {
  return TransferFunction::fromPoints("soft", {{0.0, {0.2, 0.4, 1.0}}, {1.0, {1.0, 0.9, 0.6}}},
                                      {{0.0, 0.0}, {0.3, 0.0}, {1.0, 0.25}});
}

TransferFunction marschnerLobbIsoTf() {
  return TransferFunction::fromPoints(
      "iso", {{0.0, {1.0, 0.8, 0.5}}, {1.0, {1.0, 0.8, 0.5}}},
      {{0.0, 0.0}, {0.46, 0.0}, {0.5, 1.0}, {0.54, 0.0}, {1.0, 0.0}});
}

}  // namespace tessera::lattice
