#include "tessera/lattice/MarschnerLobb.h"

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

}  // namespace tessera::lattice
