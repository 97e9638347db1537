#pragma once
// An in-core volume as a MultiresSource: the mean pyramid of lod::downsample
// by `factor` per level (2 on every axis by default; (1, 2, 2) keeps z as
// microscopy pyramids do), each level made from the one before (so level
// l+1 has ceil(dims_l / factor) voxels, the MultiresSource contract), down
// to the first level whose longest reduced side is at most `coarsestSide`.
// readBox copies a box.
// Lets the bricked layout render any volume that fits in host memory, so
// that it can be compared with the in-core layouts voxel for voxel.
#include <memory>
#include <vector>

#include "tessera/lod/MultiresSource.h"

namespace tessera::lod {

class InCoreMultiresSource final : public MultiresSource {
 public:
  explicit InCoreMultiresSource(std::shared_ptr<const Volume> volume, int coarsestSide = 16,
                                glm::ivec3 factor = glm::ivec3(2));

  const Volume& shape() const override { return shape_; }
  int levelCount() const override { return static_cast<int>(levels_.size()); }
  LevelInfo levelInfo(int level) const override;
  Volume readBox(int level, const VoxelBox& box) const override;
  std::string describe() const override;
  bool meanPyramid() const override { return true; }  // lod::downsample
  bool readsFromHostMemory() const override { return true; }

  // The level's voxels (level 0 is the volume given).
  const Volume& level(int level) const;

 private:
  Volume shape_;
  std::vector<std::shared_ptr<const Volume>> levels_;
};

// Copies `box` of `volume` into a volume of box.size() voxels with the
// volume's type, spacing and direction and its origin at the box's first
// voxel. Error if the box is empty or outside the volume.
Volume copyBox(const Volume& volume, const VoxelBox& box);

// The level dims of a pyramid reducing by `factor` a level (ceil) from
// `dims` down to the first level whose longest side among the reduced axes
// (factor > 1) is at most `coarsestSide`.
std::vector<glm::ivec3> pyramidDims(glm::ivec3 dims, int coarsestSide,
                                    glm::ivec3 factor = glm::ivec3(2));

}  // namespace tessera::lod
