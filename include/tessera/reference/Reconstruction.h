#pragma once
// The continuous field the CPU reference samples: how voxel values become a
// value (and a gradient) at any point of the volume's box. Trilinear is the
// field of every Cartesian layout; an FCC box spline or a bricked source
// supplies its own, so that it gets a reference too.
#include <memory>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"

namespace tessera {

class Reconstruction {
 public:
  virtual ~Reconstruction() = default;
  // Raw value at p in [0,1]^3, the volume box in texture space (voxel
  // centres at (i + 0.5) / dims, clamp to edge outside).
  virtual double value(glm::dvec3 p) const = 0;
  // Gradient of value() per texture-space unit. The default is the GLSL
  // seam's (layout/gradient.glsl): central differences one voxel apart along
  // each axis, through value(); a field with an analytic derivative
  // overrides it.
  virtual glm::dvec3 gradient(glm::dvec3 p) const;
  // Samples per texture-space unit along each axis (the grid's dims): the
  // central-difference step is one over it.
  virtual glm::ivec3 dims() const = 0;
  // How far from a point, in voxels, the voxels that influence its value
  // reach (trilinear: 1). Empty-space skipping widens each block's min/max
  // by this much so that every sample inside the block lies within it.
  virtual int supportVoxels() const = 0;
};

// A Cartesian volume's raw values, NaN/Inf voxels read as
// Volume::nonFiniteValue() (as the layouts upload them): what the trilinear
// and the nearest-neighbour reconstruction read.
class GridReconstruction : public Reconstruction {
 public:
  glm::ivec3 dims() const override { return dims_; }
  int supportVoxels() const override { return 1; }

 protected:
  explicit GridReconstruction(const Volume& volume);
  double at(int x, int y, int z) const {
    return data_[(static_cast<std::size_t>(z) * dims_.y + y) * dims_.x + x];
  }

 private:
  glm::ivec3 dims_;
  std::vector<double> data_;
};

// Trilinear interpolation of the volume's values.
class TrilinearReconstruction final : public GridReconstruction {
 public:
  explicit TrilinearReconstruction(const Volume& volume) : GridReconstruction(volume) {}
  double value(glm::dvec3 p) const override;
};

// Nearest neighbour: the value of the voxel whose cell holds p (label
// volumes); the GLSL twin is fieldValue() with NEAREST (render/sample.glsl).
class NearestReconstruction final : public GridReconstruction {
 public:
  explicit NearestReconstruction(const Volume& volume) : GridReconstruction(volume) {}
  double value(glm::dvec3 p) const override;
};

// A coarser level of a pyramid over the finest level's box, as the bricks
// layout samples it (layout/bricks.glsl, lod/BrickGrid.h): with `scale` the
// finest voxels per level voxel along each axis (lod::levelScale: 2^l in a
// factor-2 pyramid, (1, 2^l, 2^l) where z is kept), level voxel i covers
// finest voxels [i scale, (i + 1) scale), so p (clamped to the box, as the
// layout clamps it) is level coordinate p finestDims / scale, voxel centres
// at i + 0.5, trilinear with clamp to edge. Where the scale does not divide
// the finest dims the level reaches past the box and p = 1 falls short of
// its last centre. With `nearest`, p first moves to the centre of the finest
// voxel holding it (render/sample.glsl's fieldValue under NEAREST, which
// then samples the layout). dims() are the finest: the GPU's central
// differences step one finest voxel (layout/gradient.glsl). Scale 1 is the
// volume's trilinear (or nearest) field.
class PyramidLevelReconstruction final : public Reconstruction {
 public:
  PyramidLevelReconstruction(const Volume& level, glm::ivec3 scale, glm::ivec3 finestDims,
                             bool nearest = false);
  double value(glm::dvec3 p) const override;
  glm::ivec3 dims() const override { return finest_; }
  int supportVoxels() const override;
  glm::ivec3 scale() const { return levelScale_; }

 private:
  TrilinearReconstruction values_;
  glm::ivec3 levelScale_;
  glm::ivec3 finest_;
  glm::dvec3 scale_;  // box texture space -> the level's
  bool nearest_;
};

}  // namespace tessera
