#pragma once
// Which brick of which level each part of the volume should be drawn from
// for a view (Schultz 2016 §7.1.2: choose the resolution the screen can
// show; DESIGN.md "Large data": level choice by projected voxel size and
// budget). Starting from the coarsest level, the brick whose voxels look
// largest on screen (voxel size / pixel footprint at the brick's nearest
// point) is replaced by its children while its voxels are larger than
// `pixelsPerVoxel` pixels and the cut stays within `capacity` bricks; bricks
// the transfer function makes transparent are left out (never fetched).
#include <cstddef>
#include <functional>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/lod/BrickGrid.h"

namespace tessera::lod {

struct LodView {
  glm::dvec3 eye{0.0};      // camera position in level-0 continuous voxel coordinates
  glm::dvec3 spacing{1.0};  // level-0 spacing (world units per voxel)
  bool orthographic = false;
  // World size of one pixel: perspective, per world unit of distance
  // (2 tan(fov/2) / image height); orthographic, absolute.
  double pixelSize = 0.0;
  double pixelsPerVoxel = 1.0;  // refine while a voxel covers more pixels than this
};

struct LodSelection {
  std::vector<BrickKey> bricks;  // the cut, nearest first
  std::vector<int> bricksPerLevel;
  bool limitedByCapacity = false;  // some brick stayed coarser than the view asked
};

// `visible(key)`: false if the brick is known or estimated to be transparent.
// `capacity`: how many bricks below the coarsest level the cut may hold (the
// coarsest level is always resident: it is what everything falls back to).
LodSelection selectBricks(const BrickGrid& grid, const LodView& view,
                          const std::function<bool(const BrickKey&)>& visible,
                          std::size_t capacity);

// World distance from the eye to the brick's region (0 inside).
double brickDistance(const BrickGrid& grid, const BrickKey& key, const LodView& view);

}  // namespace tessera::lod
