#pragma once
// Min/max of raw values per block of voxels, with a one-voxel apron so that
// every trilinear sample taken inside a block lies within [min, max]: a sample
// at continuous voxel coordinate u in [bB, (b+1)B] interpolates voxels
// floor(u - 0.5) .. floor(u - 0.5) + 1, i.e. bB - 1 .. (b+1)B.
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"

namespace tessera::render {

class BlockMinMax {
 public:
  BlockMinMax() = default;
  BlockMinMax(const Volume& volume, int blockSize);

  int blockSize() const { return blockSize_; }
  glm::ivec3 blockCount() const { return count_; }
  std::size_t index(int bx, int by, int bz) const {
    return (static_cast<std::size_t>(bz) * count_.y + by) * count_.x + bx;
  }
  const std::vector<float>& mins() const { return min_; }
  const std::vector<float>& maxs() const { return max_; }

 private:
  int blockSize_ = 8;
  glm::ivec3 count_{0};
  std::vector<float> min_;
  std::vector<float> max_;
};

}  // namespace tessera::render
