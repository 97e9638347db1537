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
  HostBudget::global().check(n * 8, "precomputed gradient");
  // The values once as floats (exact for 8- and 16-bit voxels), then
  // neighbours by index arithmetic.
  std::vector<float> values(n);
  if (volume.type() == ScalarType::U8) {
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(volume.bytes().data());
    for (std::size_t i = 0; i < n; ++i) values[i] = bytes[i];
  } else {
    for (std::size_t i = 0; i < n; ++i)
      values[i] = static_cast<float>(volume.finiteValueAtIndex(i));
  }
  const std::size_t sx = 1;
  const std::size_t sy = static_cast<std::size_t>(d.x);
  const std::size_t sz = sy * static_cast<std::size_t>(d.y);
  // Two passes (the scale, then the codes): no copy of the gradients next
  // to the 4 bytes per voxel that are kept.
  auto forEachVoxel = [&](auto visit) {
    std::size_t i = 0;
    for (int z = 0; z < d.z; ++z) {
      const std::size_t zm = z > 0 ? sz : 0, zp = z + 1 < d.z ? sz : 0;
      for (int y = 0; y < d.y; ++y) {
        const std::size_t ym = y > 0 ? sy : 0, yp = y + 1 < d.y ? sy : 0;
        for (int x = 0; x < d.x; ++x, ++i) {
          const std::size_t xm = x > 0 ? sx : 0, xp = x + 1 < d.x ? sx : 0;
          visit(i, 0.5f * (values[i + xp] - values[i - xm]),
                0.5f * (values[i + yp] - values[i - ym]), 0.5f * (values[i + zp] - values[i - zm]));
        }
      }
    }
  };
  float largest[3] = {0.0f, 0.0f, 0.0f};
  forEachVoxel([&](std::size_t, float gx, float gy, float gz) {
    largest[0] = std::max(largest[0], std::abs(gx));
    largest[1] = std::max(largest[1], std::abs(gy));
    largest[2] = std::max(largest[2], std::abs(gz));
  });
  float perCode[3];
  for (int a = 0; a < 3; ++a) {
    g.step[a] = largest[a] > 0.0f ? largest[a] / VoxelGradients::kCodeRange : 1.0;
    perCode[a] = static_cast<float>(1.0 / g.step[a]);
  }
  g.texels.assign(4 * n, 255);
  g.valuesInAlpha = volume.type() == ScalarType::U8;
  constexpr float kRange = static_cast<float>(VoxelGradients::kCodeRange);
  auto code = [&](float c, int a) {
    const float q = std::clamp(std::nearbyint(c * perCode[a]), -kRange, kRange);
    return static_cast<std::uint8_t>(VoxelGradients::kZeroCode + static_cast<int>(q));
  };
  forEachVoxel([&](std::size_t i, float gx, float gy, float gz) {
    std::uint8_t* t = &g.texels[4 * i];
    t[0] = code(gx, 0);
    t[1] = code(gy, 1);
    t[2] = code(gz, 2);
    if (g.valuesInAlpha) t[3] = static_cast<std::uint8_t>(values[i]);
  });
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
