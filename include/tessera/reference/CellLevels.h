#pragma once
// The levels a streamed frame mixes (layout/BricksLayout.h): its page table
// names, per level-0 brick cell, the pyramid level the GPU samples there
// (the finest resident brick over the cell), so one frame shows level 0
// where the atlas holds it and coarser levels elsewhere. The reference of
// such a frame reads the same level in the same cell (CellLevels::levelAt)
// and samples that level as layout/bricks.glsl does (sampleLevel, or
// CellLevelsReconstruction for a single-channel frame's field).
#include <memory>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"
#include "tessera/reference/Reconstruction.h"

namespace tessera {

struct CellLevels {
  glm::ivec3 finestDims{0};  // level-0 voxels
  int brickSize = 0;         // B: a cell is B^3 level-0 voxels (the last one per axis partial)
  glm::ivec3 cells{0};       // ceil(finestDims / B)
  std::vector<int> levels;   // per cell, x fastest: the level shown, -1 a transparent constant

  // The cell holding p in [0,1]^3 (clamped to the box), as bricks.glsl's
  // brickPage finds it: min(floor(p finestDims / B), cells - 1).
  int levelAt(glm::dvec3 p) const;
  // Cells per level (index = level) and, last, the transparent ones.
  std::vector<int> cellsPerLevel() const;
  // Whether more than one level is shown.
  bool mixed() const;
};

// Level `level` of a pyramid (its voxels; `scale` level-0 voxels per level
// voxel along each axis, lod::levelScale) at p in [0,1]^3 of level 0's box:
// level coordinate p finestDims / scale, voxel centres at i + 0.5,
// trilinear with clamp to edge, p clamped to the box: the field
// PyramidLevelReconstruction samples (reference/Reconstruction.h), read from
// the volume itself rather than a double-precision copy.
double sampleLevel(const Volume& level, glm::ivec3 scale, glm::ivec3 finestDims, glm::dvec3 p);

// The field a single-channel streamed frame shows: at p, the field of the
// level p's cell shows (each a PyramidLevelReconstruction over level 0's
// box, as bricks.glsl samples that level's brick); a transparent cell (-1)
// reads `transparentLevel` (the GPU returns a constant the transfer function
// hides there; the level whose brick was judged transparent is not kept).
// Gradients are central differences through value(), each offset sample in
// its own cell, as layout/gradient.glsl differentiates the page-table
// lookups. InputError when a cell names a level `levels` does not hold.
class CellLevelsReconstruction final : public Reconstruction {
 public:
  CellLevelsReconstruction(CellLevels cells,
                           std::vector<std::shared_ptr<const Reconstruction>> levels,
                           int transparentLevel);
  double value(glm::dvec3 p) const override;
  glm::ivec3 dims() const override { return cells_.finestDims; }
  // The widest support of the levels read: a sample near a cell's side
  // reads the coarsest level next to it.
  int supportVoxels() const override { return support_; }
  const CellLevels& cells() const { return cells_; }

 private:
  CellLevels cells_;
  std::vector<std::shared_ptr<const Reconstruction>> levels_;  // [level], null where not shown
  int transparentLevel_;
  int support_ = 1;
};

}  // namespace tessera
