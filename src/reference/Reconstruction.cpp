#include "tessera/reference/Reconstruction.h"

#include <algorithm>

#include <glm/common.hpp>

namespace tessera {

glm::dvec3 Reconstruction::gradient(glm::dvec3 p) const {
  const glm::dvec3 h = 1.0 / glm::dvec3(dims());
  glm::dvec3 g;
  for (int a = 0; a < 3; ++a) {
    glm::dvec3 d(0.0);
    d[a] = h[a];
    g[a] = (value(p + d) - value(p - d)) / (2.0 * h[a]);
  }
  return g;
}

GridReconstruction::GridReconstruction(const Volume& volume) : dims_(volume.dims()) {
  data_.resize(static_cast<std::size_t>(volume.voxelCount()));
  for (std::size_t i = 0; i < data_.size(); ++i) data_[i] = volume.finiteValueAtIndex(i);
}

double TrilinearReconstruction::value(glm::dvec3 p) const {
  const glm::ivec3 d = dims();
  // Continuous voxel coordinate with centres at integers.
  const glm::dvec3 u = p * glm::dvec3(d) - 0.5;
  const glm::dvec3 f = glm::floor(u);
  const glm::dvec3 w = u - f;
  const glm::ivec3 i0 = glm::clamp(glm::ivec3(f), glm::ivec3(0), d - 1);
  const glm::ivec3 i1 = glm::clamp(glm::ivec3(f) + 1, glm::ivec3(0), d - 1);
  const double c00 = at(i0.x, i0.y, i0.z) * (1 - w.x) + at(i1.x, i0.y, i0.z) * w.x;
  const double c10 = at(i0.x, i1.y, i0.z) * (1 - w.x) + at(i1.x, i1.y, i0.z) * w.x;
  const double c01 = at(i0.x, i0.y, i1.z) * (1 - w.x) + at(i1.x, i0.y, i1.z) * w.x;
  const double c11 = at(i0.x, i1.y, i1.z) * (1 - w.x) + at(i1.x, i1.y, i1.z) * w.x;
  const double c0 = c00 * (1 - w.y) + c10 * w.y;
  const double c1 = c01 * (1 - w.y) + c11 * w.y;
  return c0 * (1 - w.z) + c1 * w.z;
}

double NearestReconstruction::value(glm::dvec3 p) const {
  const glm::ivec3 d = dims();
  const glm::ivec3 i = glm::clamp(glm::ivec3(glm::floor(p * glm::dvec3(d))), glm::ivec3(0), d - 1);
  return at(i.x, i.y, i.z);
}

PyramidLevelReconstruction::PyramidLevelReconstruction(const Volume& level, glm::ivec3 scale,
                                                       glm::ivec3 finestDims, bool nearest)
    : values_(level),
      levelScale_(scale),
      finest_(finestDims),
      scale_(glm::dvec3(finestDims) / (glm::dvec3(level.dims()) * glm::dvec3(scale))),
      nearest_(nearest) {}

int PyramidLevelReconstruction::supportVoxels() const {
  return std::max({levelScale_.x, levelScale_.y, levelScale_.z});
}

double PyramidLevelReconstruction::value(glm::dvec3 p) const {
  p = glm::clamp(p, 0.0, 1.0);
  if (nearest_) {
    const glm::dvec3 d(finest_);
    p = (glm::clamp(glm::floor(p * d), glm::dvec3(0.0), d - 1.0) + 0.5) / d;
  }
  return values_.value(p * scale_);
}

}  // namespace tessera
