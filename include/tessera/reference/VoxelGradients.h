#pragma once
// A precomputed gradient field (docs/shading.md): per voxel the central
// difference of its neighbours' raw values, (v[i+1] - v[i-1]) / 2 along each
// axis (indices clamped to the volume), quantised to 8 bits per component
// with a per-axis scale so that zero stays exact, and interpolated
// trilinearly between voxel centres. Away from the volume's outermost half
// voxel this is exactly the central difference of the trilinear field that
// Reconstruction::gradient takes (trilinear weights commute with a one-voxel
// shift), up to the quantisation; in that half-voxel shell clamping differs.
// The GPU's twin is the RGBA8 3D texture of layout/GradientTexture.h; the
// reference lights the same field through VoxelGradientReconstruction.
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"
#include "tessera/reference/Reconstruction.h"

namespace tessera {

struct VoxelGradients {
  glm::ivec3 dims{0};
  // RGBA8 texels, x fastest: code c per axis, difference = (c - 128) * step
  // (raw value per voxel); alpha the voxel's own raw value where
  // valuesInAlpha (8-bit volumes), 255 otherwise.
  std::vector<std::uint8_t> texels;
  // Whether alpha holds the voxels: one trilinear fetch then gives a lit
  // sample's value (raw / 255) and gradient (layout/gradient_texture.glsl).
  bool valuesInAlpha = false;
  glm::dvec3 step{0.0};  // raw value per voxel per code unit: max |difference| / 127

  static constexpr int kZeroCode = 128;
  static constexpr double kCodeRange = 127.0;

  // The decoded difference of voxel (x, y, z), raw value per voxel.
  glm::dvec3 at(int x, int y, int z) const;
};

// One pass over the volume (non-finite voxels read as the layouts upload them).
VoxelGradients computeVoxelGradients(const Volume& volume);

// Values from `values` (e.g. TrilinearReconstruction of the same volume), the
// gradient from the trilinear interpolation of `gradients` (per texture-space
// unit, raw values): the field a ray caster with a precomputed gradient
// texture shades.
class VoxelGradientReconstruction final : public Reconstruction {
 public:
  // Both must outlive this object.
  VoxelGradientReconstruction(const Reconstruction& values, const VoxelGradients& gradients);
  double value(glm::dvec3 p) const override { return values_.value(p); }
  glm::dvec3 gradient(glm::dvec3 p) const override;
  glm::ivec3 dims() const override { return values_.dims(); }
  int supportVoxels() const override { return values_.supportVoxels(); }

 private:
  const Reconstruction& values_;
  const VoxelGradients& gradients_;
};

}  // namespace tessera
