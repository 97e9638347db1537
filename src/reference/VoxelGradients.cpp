#include "tessera/reference/VoxelGradients.h"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"

namespace tessera {

glm::dvec3 VoxelGradients::at(int x, int y, int z) const {
  const std::size_t i = 4 * ((static_cast<std::size_t>(z) * dims.y + y) * dims.x + x);
  return glm::dvec3(texels[i] - kZeroCode, texels[i + 1] - kZeroCode, texels[i + 2] - kZeroCode) *
         step;
}

VoxelGradients computeVoxelGradients(const Volume& volume) {
  VoxelGradients g;
  g.dims = volume.dims();
  const glm::ivec3 d = g.dims;
  const std::size_t n = static_cast<std::size_t>(volume.voxelCount());
  HostBudget::global().check(n * 16, "precomputed gradient");
  std::vector<float> diff(3 * n);
  auto value = [&](int x, int y, int z) {
    x = std::clamp(x, 0, d.x - 1);
    y = std::clamp(y, 0, d.y - 1);
    z = std::clamp(z, 0, d.z - 1);
    return volume.finiteValueAtIndex(volume.index(x, y, z));
  };
  glm::dvec3 largest(0.0);
  std::size_t i = 0;
  for (int z = 0; z < d.z; ++z) {
    for (int y = 0; y < d.y; ++y) {
      for (int x = 0; x < d.x; ++x, ++i) {
        const glm::dvec3 c(0.5 * (value(x + 1, y, z) - value(x - 1, y, z)),
                           0.5 * (value(x, y + 1, z) - value(x, y - 1, z)),
                           0.5 * (value(x, y, z + 1) - value(x, y, z - 1)));
        for (int a = 0; a < 3; ++a) {
          diff[3 * i + a] = static_cast<float>(c[a]);
          largest[a] = std::max(largest[a], std::abs(c[a]));
        }
      }
    }
  }
  for (int a = 0; a < 3; ++a) {
    g.step[a] = largest[a] > 0.0 ? largest[a] / VoxelGradients::kCodeRange : 1.0;
  }
  g.texels.assign(4 * n, 255);
  for (std::size_t v = 0; v < n; ++v) {
    for (int a = 0; a < 3; ++a) {
      const double code = std::round(diff[3 * v + a] / g.step[a]);
      g.texels[4 * v + a] = static_cast<std::uint8_t>(
          VoxelGradients::kZeroCode +
          std::clamp(code, -VoxelGradients::kCodeRange, VoxelGradients::kCodeRange));
    }
  }
  return g;
}

VoxelGradientReconstruction::VoxelGradientReconstruction(const Reconstruction& values,
                                                         const VoxelGradients& gradients)
    : values_(values), gradients_(gradients) {
  if (values.dims() != gradients.dims) {
    throw Error("precomputed gradient: its grid does not match the field's");
  }
}

glm::dvec3 VoxelGradientReconstruction::gradient(glm::dvec3 p) const {
  // Trilinear, voxel centres at (i + 0.5) / dims, clamp to edge: as the GPU
  // filters the RGBA8 texture.
  const glm::ivec3 d = gradients_.dims;
  const glm::dvec3 u = p * glm::dvec3(d) - 0.5;
  const glm::dvec3 f = glm::floor(u);
  const glm::dvec3 w = u - f;
  const glm::ivec3 i0 = glm::clamp(glm::ivec3(f), glm::ivec3(0), d - 1);
  const glm::ivec3 i1 = glm::clamp(glm::ivec3(f) + 1, glm::ivec3(0), d - 1);
  auto at = [&](int x, int y, int z) { return gradients_.at(x, y, z); };
  const glm::dvec3 c00 = at(i0.x, i0.y, i0.z) * (1 - w.x) + at(i1.x, i0.y, i0.z) * w.x;
  const glm::dvec3 c10 = at(i0.x, i1.y, i0.z) * (1 - w.x) + at(i1.x, i1.y, i0.z) * w.x;
  const glm::dvec3 c01 = at(i0.x, i0.y, i1.z) * (1 - w.x) + at(i1.x, i0.y, i1.z) * w.x;
  const glm::dvec3 c11 = at(i0.x, i1.y, i1.z) * (1 - w.x) + at(i1.x, i1.y, i1.z) * w.x;
  const glm::dvec3 c0 = c00 * (1 - w.y) + c10 * w.y;
  const glm::dvec3 c1 = c01 * (1 - w.y) + c11 * w.y;
  // Raw value per voxel -> per texture-space unit.
  return (c0 * (1 - w.z) + c1 * w.z) * glm::dvec3(d);
}

}  // namespace tessera
