#pragma once
// Min/max of raw values per block of voxels, widened by the reconstruction's
// support so that every sample taken inside a block lies within [min, max]:
// with support r (trilinear: 1), a sample at continuous voxel coordinate u in
// [bB, (b+1)B] depends on voxels floor(u - 0.5) - (r - 1) .. floor(u - 0.5) + r,
// i.e. bB - r .. (b+1)B + r - 1. The layout owns this (Layout::valueBlocks),
// because only it knows where its voxels are (in core, bricks on disk, an FCC
// lattice) and what reconstruction its sampleVolume() uses.
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"

namespace tessera::layout {

class ValueBlocks {
 public:
  ValueBlocks() = default;
  // NaN/Inf voxels count as Volume::nonFiniteValue(), the value they render as.
  ValueBlocks(const Volume& volume, int blockSize, int supportVoxels);
  // Ranges computed by the layout itself (count.x * count.y * count.z each,
  // x fastest), e.g. from an FCC lattice's coefficients or per-brick ranges.
  ValueBlocks(glm::ivec3 count, int blockSize, int supportVoxels, std::vector<float> mins,
              std::vector<float> maxs);

  int blockSize() const { return blockSize_; }
  int supportVoxels() const { return support_; }
  glm::ivec3 blockCount() const { return count_; }
  std::size_t index(int bx, int by, int bz) const {
    return (static_cast<std::size_t>(bz) * count_.y + by) * count_.x + bx;
  }
  const std::vector<float>& mins() const { return min_; }
  const std::vector<float>& maxs() const { return max_; }

 private:
  int blockSize_ = 8;
  int support_ = 1;
  glm::ivec3 count_{0};
  std::vector<float> min_;
  std::vector<float> max_;
};

}  // namespace tessera::layout
