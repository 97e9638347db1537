#pragma once
// Shared by the bricks tests: options that put every brick at level 0 and
// read inline (deterministic residency), refinement until every wanted
// brick is resident, and every brick's stored range per level.
#include <gtest/gtest.h>

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "tessera/core/Camera.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/layout/BricksLayout.h"
#include "tessera/lod/BrickGrid.h"
#include "tessera/lod/MultiresSource.h"

namespace tessera::test {

inline layout::BricksOptions levelZeroBricks(int brickSize, bool walk = true) {
  layout::BricksOptions o;
  o.brickSize = brickSize;
  o.pixelsPerVoxel = 0.05;  // every brick at level 0 for these small volumes
  o.workers = 0;            // inline reads: deterministic residency
  o.walk = walk;
  return o;
}

// Streams frames of `image`^2 until every brick the view wants is resident.
inline void refineBricks(layout::BricksLayout& bricks, const Camera& cam,
                         const TransferFunction& tf, int image) {
  for (int frame = 1; frame <= 400; ++frame) {
    const layout::BricksFrame f = bricks.update(cam, image, image, tf);
    if (f.complete) return;
    if (f.uploaded == 0) bricks.waitForBricks(20.0);
  }
  ADD_FAILURE() << "bricks never completed";
}

// Every brick's stored min/max, per level (read through `mapping`).
inline std::vector<std::unordered_map<std::uint64_t, lod::BrickRange>> storedRanges(
    const lod::MultiresSource& source, const lod::BrickGrid& grid,
    const lod::StoredMapping& mapping) {
  std::vector<std::unordered_map<std::uint64_t, lod::BrickRange>> ranges(
      static_cast<std::size_t>(grid.levelCount()));
  for (int l = 0; l < grid.levelCount(); ++l) {
    const glm::ivec3 n = grid.bricks(l);
    for (int z = 0; z < n.z; ++z)
      for (int y = 0; y < n.y; ++y)
        for (int x = 0; x < n.x; ++x) {
          const lod::BrickKey k{l, {x, y, z}};
          const lod::StoredBrick b = lod::readStoredBrick(source, grid, k, mapping);
          ranges[static_cast<std::size_t>(l)][k.id()] = {b.min, b.max};
        }
  }
  return ranges;
}

}  // namespace tessera::test
