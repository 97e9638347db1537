#include "tessera/lattice/BoxSplineReconstruction.h"

namespace tessera::lattice {

BoxSplineReconstruction::BoxSplineReconstruction(const FccVolume& volume) : spline_(volume) {}

glm::dvec3 BoxSplineReconstruction::gridCoord(glm::dvec3 p) const {
  return p * glm::dvec3(spline_.gridDims()) - 0.5;
}

double BoxSplineReconstruction::value(glm::dvec3 p) const {
  return spline_.value(gridCoord(p));
}

glm::dvec3 BoxSplineReconstruction::gradient(glm::dvec3 p) const {
  return spline_.sample(gridCoord(p)).gradient * glm::dvec3(spline_.gridDims());
}

}  // namespace tessera::lattice
