#pragma once
// Where the layout tests probe sampleVolume() (layout/LayoutProbe.h) against
// the CPU's trilinear field: one set for every layout, so a position that
// found a seam in one layout is tried on all.
#include <cmath>
#include <vector>

#include <glm/vec3.hpp>

namespace tessera::test {

// A deterministic scatter over the whole box, plus positions that test the
// tile borders in x and y (the edge texel centres, just inside and outside
// them, and the box faces, where an in-tile clamp must reproduce
// clamp-to-edge) and, in z, between every pair of neighbouring slices: those
// include every seam of the packed layouts (dense: channel 3 -> channel 0 of
// the next tile, possibly in the next texture; overlapped: the pairs in
// channels B, A and the next tile's R, G, which repeats A).
inline std::vector<glm::vec3> probePositions(glm::ivec3 d) {
  std::vector<glm::vec3> p;
  for (int i = 0; i < 4000; ++i) {
    p.emplace_back(std::fmod(i * 0.6180339887f, 1.0f), std::fmod(i * 0.7548776662f, 1.0f),
                   std::fmod(i * 0.5698402910f, 1.0f));
  }
  const auto edges = [](int n) {
    const float t = 1.0f / static_cast<float>(n);
    return std::vector<float>{0.0f,
                              0.25f * t,
                              0.5f * t,
                              0.5f * t + 1e-4f,
                              0.75f * t,
                              1.0f - 0.75f * t,
                              1.0f - 0.5f * t - 1e-4f,
                              1.0f - 0.5f * t,
                              1.0f - 0.25f * t,
                              1.0f};
  };
  int k = 0;
  for (float x : edges(d.x)) {
    for (float y : edges(d.y)) {
      const float z = std::fmod(0.37f + 0.2357f * static_cast<float>(k++), 1.0f);
      p.emplace_back(x, y, z);
    }
  }
  for (float z : edges(d.z)) {
    for (int i = 0; i < 20; ++i) p.emplace_back(0.05f * i, 1.0f - 0.05f * i, z);
  }
  for (int s = 0; s + 1 < d.z; ++s) {
    for (float f : {0.0f, 0.1f, 0.3f, 0.5f, 0.7f, 0.9f, 1.0f}) {
      const float z = (static_cast<float>(s) + 0.5f + f) / static_cast<float>(d.z);
      for (int i = 0; i < 12; ++i) {
        p.emplace_back(std::fmod(0.03f + i * 0.4142f, 1.0f), std::fmod(0.07f + i * 0.7321f, 1.0f),
                       z);
      }
    }
  }
  return p;
}

}  // namespace tessera::test
