#pragma once
// Three overlapping Gaussian blobs: a smooth field, real-looking at any
// resolution, that the lattice tests resample and render.
#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"

namespace tessera::test {

// The field at p in [0,1]^3, clamped to [0,1].
inline double blobsAt(glm::dvec3 p) {
  const glm::dvec3 centres[3] = {{0.35, 0.4, 0.5}, {0.65, 0.55, 0.4}, {0.5, 0.6, 0.7}};
  double f = 0.0;
  for (const glm::dvec3& c : centres) {
    const glm::dvec3 d = p - c;
    f += 0.6 * std::exp(-glm::dot(d, d) / (2 * 0.12 * 0.12));
  }
  return std::min(f, 1.0);
}

// The field at the voxel centres of `dims`: U8 holds round(255 f), other
// types f itself.
inline Volume blobs(glm::ivec3 dims, ScalarType type) {
  Volume v = Volume::allocate(dims, type, "blobs");
  for (int z = 0; z < dims.z; ++z) {
    for (int y = 0; y < dims.y; ++y) {
      for (int x = 0; x < dims.x; ++x) {
        const double f = blobsAt((glm::dvec3(x, y, z) + 0.5) / glm::dvec3(dims));
        v.setValueAtIndex(v.index(x, y, z), type == ScalarType::U8 ? std::round(255.0 * f) : f);
      }
    }
  }
  return v;
}

}  // namespace tessera::test
