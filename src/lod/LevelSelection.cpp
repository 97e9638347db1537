#include "tessera/lod/LevelSelection.h"

#include <algorithm>
#include <cmath>
#include <queue>

namespace tessera::lod {

double brickDistance(const BrickGrid& grid, const BrickKey& key, const LodView& view) {
  const glm::dvec3 lo = grid.lowerCorner(key);
  const glm::dvec3 hi = grid.upperCorner(key);
  const glm::dvec3 nearest = glm::clamp(view.eye, lo, hi);
  return glm::length((nearest - view.eye) * view.spacing);
}

namespace {

// How many pixels one voxel of the brick's level covers at its nearest point:
// its longest world extent (a level that keeps z, (1, 2, 2), has voxels as
// deep as level 0's and twice as wide; the widest side decides).
double pixelsPerVoxel(const BrickGrid& grid, const BrickKey& key, const LodView& view) {
  const glm::dvec3 extent = view.spacing * glm::dvec3(grid.scale(key.level));
  const double voxel = std::max({extent.x, extent.y, extent.z});
  const double pixel = view.orthographic
                           ? view.pixelSize
                           : view.pixelSize * std::max(brickDistance(grid, key, view), 1e-9);
  return pixel > 0.0 ? voxel / pixel : 1e30;
}

}  // namespace

LodSelection selectBricks(const BrickGrid& grid, const LodView& view,
                          const std::function<bool(const BrickKey&)>& visible,
                          std::size_t capacity) {
  struct Item {
    double error;
    BrickKey key;
    bool operator<(const Item& o) const { return error < o.error; }
  };
  std::priority_queue<Item> open;  // bricks that might still be refined
  std::vector<BrickKey> done;      // bricks kept at their level
  const int top = grid.levelCount() - 1;
  const glm::ivec3 n = grid.bricks(top);
  std::size_t count = 0;
  for (int z = 0; z < n.z; ++z) {
    for (int y = 0; y < n.y; ++y) {
      for (int x = 0; x < n.x; ++x) {
        const BrickKey k{top, {x, y, z}};
        if (!visible(k)) continue;
        open.push({pixelsPerVoxel(grid, k, view), k});
      }
    }
  }
  LodSelection out;
  while (!open.empty()) {
    const Item item = open.top();
    open.pop();
    if (item.key.level == 0 || item.error <= view.pixelsPerVoxel) {
      done.push_back(item.key);
      continue;
    }
    std::vector<BrickKey> kids = grid.children(item.key);
    kids.erase(
        std::remove_if(kids.begin(), kids.end(), [&](const BrickKey& k) { return !visible(k); }),
        kids.end());
    // The coarsest bricks are pinned: refining one frees no slot.
    const std::size_t after = count + kids.size() - (item.key.level == top ? 0 : 1);
    if (after > capacity) {
      out.limitedByCapacity = true;
      done.push_back(item.key);
      continue;
    }
    count = after;
    for (const BrickKey& k : kids) open.push({pixelsPerVoxel(grid, k, view), k});
  }
  std::vector<std::pair<double, BrickKey>> byDistance;
  for (const BrickKey& k : done) byDistance.emplace_back(brickDistance(grid, k, view), k);
  std::stable_sort(byDistance.begin(), byDistance.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  out.bricksPerLevel.assign(static_cast<std::size_t>(grid.levelCount()), 0);
  for (const auto& [d, k] : byDistance) {
    out.bricks.push_back(k);
    ++out.bricksPerLevel[static_cast<std::size_t>(k.level)];
  }
  return out;
}

}  // namespace tessera::lod
