#pragma once
// Procedural volumes at any size, for tests and for data we may not ship.
#include <string>

#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"

namespace tessera {

// Solid sphere of value 255 (u8), radius 0.4 of the smallest extent, with a
// smooth 1-voxel edge; background 0.
Volume makeSphere(glm::ivec3 dims);

// 3D Shepp–Logan phantom (Kak & Slaney's ten ellipsoids, the "modified"
// contrast of Toft), u8 with intensities scaled so the brightest region is 255.
// The phantom spans [-1,1] on every axis, sampled at voxel centres; spacing
// is max(dims)/dims: a cube in world space, 1 along the longest axis.
Volume makeSheppLogan(glm::ivec3 dims);

// Marschner–Lobb test signal (Marschner & Lobb 1994, fM = 6, alpha = 0.25)
// sampled on [-1,1]^3 including both ends; spacing 1 along the longest axis,
// stored as f32 in [0,1] with the value window fixed to [0,1].
Volume makeMarschnerLobb(glm::ivec3 dims);

// Parses "gen:NAME[:N|:WxHxD]" where NAME is sphere, shepp-logan or
// marschner-lobb; default size 64³ (41³ for marschner-lobb).
// InputError on an unknown name or malformed size.
Volume makeProcedural(const std::string& spec);

}  // namespace tessera
