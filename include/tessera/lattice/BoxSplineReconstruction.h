#pragma once
// The CPU reference's field for FCC volumes: the six-direction box spline of
// an FccVolume's samples (FccBoxSpline.h), over the box of the Cartesian
// volume it came from, so that
//   renderReference(fcc.box(), BoxSplineReconstruction(fcc), tf, camera, ...)
// renders FCC data with the same rays, samples and compositing as the
// trilinear reference of the original.
#include "tessera/lattice/FccBoxSpline.h"
#include "tessera/lattice/FccVolume.h"
#include "tessera/reference/Reconstruction.h"

namespace tessera::lattice {

class BoxSplineReconstruction final : public tessera::Reconstruction {
 public:
  explicit BoxSplineReconstruction(const FccVolume& volume);
  // p in [0,1]^3 of the box: grid coordinate u = p * gridDims - 0.5.
  double value(glm::dvec3 p) const override;
  // The spline's exact gradient, per texture-space unit.
  glm::dvec3 gradient(glm::dvec3 p) const override;
  glm::ivec3 dims() const override { return spline_.gridDims(); }
  // K reaches 2 grid units along each axis (its support is |x|_inf <= 2).
  int supportVoxels() const override { return 2; }

 private:
  glm::dvec3 gridCoord(glm::dvec3 p) const;

  FccBoxSpline spline_;
};

}  // namespace tessera::lattice
