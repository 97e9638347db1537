#pragma once
// The Marschner-Lobb test signal as a function, to sample it on the FCC
// lattice directly and to measure reconstructions against it.
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/core/Camera.h"
#include "tessera/core/TransferFunction.h"

#include "tessera/core/Volume.h"
#include "tessera/lattice/FccVolume.h"
#include "tessera/reference/Reconstruction.h"

namespace tessera::lattice {

// Marschner & Lobb (1994), "An evaluation of reconstruction filters for
// volume rendering", eq. 2 with f_M = 6 and alpha = 0.25, at x in [-1,1]^3;
// values in [0, 1].
double marschnerLobb(glm::dvec3 x);

// Signal coordinate of texture position p of the box of makeMarschnerLobb(dims)
// (io/Procedural.h): its voxel i sits at -1 + 2 i / (n - 1).
glm::dvec3 marschnerLobbCoordinate(glm::ivec3 dims, glm::dvec3 p);

// The signal itself as a reconstruction of the makeMarschnerLobb(dims) box:
// the exact field that the measured reconstructions are compared with.
class MarschnerLobbSignal final : public Reconstruction {
 public:
  explicit MarschnerLobbSignal(glm::ivec3 dims) : dims_(dims) {}
  double value(glm::dvec3 p) const override {
    return marschnerLobb(marschnerLobbCoordinate(dims_, p));
  }
  glm::ivec3 dims() const override { return dims_; }
  int supportVoxels() const override { return 0; }

 private:
  glm::ivec3 dims_;
};

// The signal sampled on the FCC lattice over the box of `cartesian`, a
// makeMarschnerLobb() volume (or its shape with the same geometry), and
// quasi-interpolated unless asked not to (FccResampling.h).
FccVolume makeMarschnerLobbFcc(const Volume& cartesian, FccDensity density,
                               bool quasiInterpolated = true);

// The quality study of docs/fcc.md (tessera bench --fcc, the
// MarschnerLobbQuality tests), in one place:
//
// Texture positions of the samples the ray caster takes for a size x size
// image of `box` (step 0.5 voxel of the smallest spacing, samples at
// t0 + (k + 0.5) ds inside the box).
std::vector<glm::dvec3> raySamplePositions(const Volume& box, const Camera& camera, int size);

// RMS error of `field` against the signal at texture positions `at` of the
// box of makeMarschnerLobb(dims).
double marschnerLobbRms(const Reconstruction& field, const std::vector<glm::dvec3>& at,
                        glm::ivec3 dims);

// The study's transfer functions: "soft", a ramp to opacity 0.25 over the
// upper 70 % of values, and "iso", opacity only in a narrow band around 0.5
// (an isosurface look, which shows small differences of the field).
TransferFunction marschnerLobbSoftTf();
TransferFunction marschnerLobbIsoTf();

}  // namespace tessera::lattice
