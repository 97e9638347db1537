#include "tessera/reference/FusedVolume.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/common.hpp>
#include <glm/matrix.hpp>

#include "tessera/reference/ReferenceRaycaster.h"

namespace tessera {

namespace {

// Normalised texture coordinates -> voxel index: i = p * dims - 0.5.
glm::dmat4 indexFromTexture(glm::dvec3 dims) {
  glm::dmat4 m(1.0);
  for (int a = 0; a < 3; ++a) {
    m[a][a] = dims[a];
    m[3][a] = -0.5;
  }
  return m;
}

bool inUnitBox(glm::dvec3 q) {
  return q.x >= 0.0 && q.y >= 0.0 && q.z >= 0.0 && q.x <= 1.0 && q.y <= 1.0 && q.z <= 1.0;
}

// The bounding box of the unit cube mapped by m against [0,1]^3.
bool cubeMeetsUnitBox(const glm::dmat4& m) {
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
  for (int c = 0; c < 8; ++c) {
    const glm::dvec3 q(glm::dvec4(m * glm::dvec4(c & 1, (c >> 1) & 1, (c >> 2) & 1, 1.0)));
    lo = glm::min(lo, q);
    hi = glm::max(hi, q);
  }
  return lo.x <= 1.0 && lo.y <= 1.0 && lo.z <= 1.0 && hi.x >= 0.0 && hi.y >= 0.0 && hi.z >= 0.0;
}

}  // namespace

glm::dmat4 fusedFromAnatomy(const Volume& anatomy, const Volume& fused) {
  const glm::dmat4 anatomyWorld = anatomy.indexToWorld() * indexFromTexture(anatomy.dims());
  const glm::dmat4 fusedWorld = fused.indexToWorld() * indexFromTexture(fused.dims());
  return glm::inverse(fusedWorld) * anatomyWorld;
}

bool fusedOverlaps(const Volume& anatomy, const Volume& fused) {
  const glm::dmat4 m = fusedFromAnatomy(anatomy, fused);
  return cubeMeetsUnitBox(m) && cubeMeetsUnitBox(glm::inverse(m));
}

glm::dvec4 fusedColorAt(const FusedVolume& fused, glm::dvec3 q) {
  if (!inUnitBox(q)) return glm::dvec4(0.0);
  const Volume& v = *fused.volume;
  const double ww = fused.window.width();
  double n = 0.0;
  if (fused.labels) {
    const glm::ivec3 d = v.dims();
    const glm::ivec3 cell =
        glm::clamp(glm::ivec3(glm::floor(q * glm::dvec3(d))), glm::ivec3(0), d - 1);
    n = std::clamp((v.finiteValueAtIndex(v.index(cell.x, cell.y, cell.z)) - fused.window.min) / ww,
                   0.0, 1.0);
    n = std::floor(n * 255.0 + 0.5) / 255.0;  // the nearest of the table's 256 entries
  } else {
    n = std::clamp((sampleTrilinear(v, q) - fused.window.min) / ww, 0.0, 1.0);
  }
  return glm::dvec4(fused.tf.color(n), fused.tf.opacity(n) * fused.opacity);
}

glm::dvec4 fuseSample(glm::dvec3 color, double alpha, glm::dvec4 fusedColor, double ds,
                      double unitLength) {
  const double w = std::clamp(fusedColor.a, 0.0, 1.0);
  const double a = 1.0 - std::pow(1.0 - w, ds / unitLength);
  return glm::dvec4(glm::mix(color, glm::dvec3(fusedColor), w), std::max(alpha, a));
}

glm::dvec4 FusionTwin::fuse(glm::dvec3 color, double alpha, glm::dvec3 p, double ds) const {
  const glm::dvec3 q(fusedFromAnatomy * glm::dvec4(p, 1.0));
  return fuseSample(color, alpha, fusedColorAt(fused, q), ds, fused.tf.opacityUnitLength);
}

glm::dvec3 indexOfWorld(const Volume& volume, glm::dvec3 worldMm) {
  return glm::dvec3(glm::inverse(volume.indexToWorld()) * glm::dvec4(worldMm, 1.0));
}

double fusedValueAtWorld(const FusedVolume& fused, glm::dvec3 worldMm) {
  const Volume& v = *fused.volume;
  const glm::dvec3 d(v.dims());
  const glm::dvec3 q = (indexOfWorld(v, worldMm) + 0.5) / d;
  if (!inUnitBox(q)) return std::numeric_limits<double>::quiet_NaN();
  if (!fused.labels) return sampleTrilinear(v, q);
  const glm::ivec3 cell = glm::clamp(glm::ivec3(glm::floor(q * d)), glm::ivec3(0), v.dims() - 1);
  return v.finiteValueAtIndex(v.index(cell.x, cell.y, cell.z));
}

}  // namespace tessera
