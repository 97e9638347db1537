#pragma once
// The Marschner-Lobb test signal as a function, to sample it on the FCC
// lattice directly and to measure reconstructions against it.
#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"
#include "tessera/lattice/FccVolume.h"

namespace tessera::lattice {

// Marschner & Lobb (1994), "An evaluation of reconstruction filters for
// volume rendering", eq. 2 with f_M = 6 and alpha = 0.25, at x in [-1,1]^3;
// values in [0, 1].
double marschnerLobb(glm::dvec3 x);

// Signal coordinate of texture position p of the box of makeMarschnerLobb(dims)
// (io/Procedural.h): its voxel i sits at -1 + 2 i / (n - 1).
glm::dvec3 marschnerLobbCoordinate(glm::ivec3 dims, glm::dvec3 p);

// The signal sampled on the FCC lattice over the box of `cartesian`, a
// makeMarschnerLobb() volume (or its shape with the same geometry), and
// quasi-interpolated unless asked not to (FccResampling.h).
FccVolume makeMarschnerLobbFcc(const Volume& cartesian, FccDensity density,
                               bool quasiInterpolated = true);

}  // namespace tessera::lattice
