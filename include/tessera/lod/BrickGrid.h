#pragma once
// Bricks of a multiresolution source (Schultz 2016 §7.3; DESIGN.md "Large
// data"): level l is cut into bricks of B^3 voxels (the last brick along an
// axis may be partial); each brick is stored with a one-voxel apron of its
// neighbours' voxels (replicated at the volume's faces), (B + 2)^3 voxels in
// all, so trilinear interpolation anywhere inside the brick reads only the
// brick and the bricked volume shows no seams. Brick (l, b) covers level-0
// voxels [b B 2^l, (b + 1) B 2^l); its parent is (l + 1, b / 2).
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/lod/MultiresSource.h"

namespace tessera::lod {

struct BrickKey {
  int level = 0;
  glm::ivec3 brick{0};
  // A unique number per brick (level in the top bits, then z, y, x).
  std::uint64_t id() const {
    return (static_cast<std::uint64_t>(level) << 60) | (static_cast<std::uint64_t>(brick.z) << 40) |
           (static_cast<std::uint64_t>(brick.y) << 20) | static_cast<std::uint64_t>(brick.x);
  }
  bool operator==(const BrickKey&) const = default;
};

class BrickGrid {
 public:
  BrickGrid() = default;
  BrickGrid(std::vector<glm::ivec3> levelDims, int brickSize);
  static BrickGrid of(const MultiresSource& source, int brickSize);

  int brickSize() const { return brickSize_; }
  int stored() const { return brickSize_ + 2; }  // with the apron
  std::uint64_t storedVoxels() const {
    return static_cast<std::uint64_t>(stored()) * stored() * stored();
  }
  int levelCount() const { return static_cast<int>(dims_.size()); }
  glm::ivec3 dims(int level) const { return dims_[static_cast<std::size_t>(level)]; }
  glm::ivec3 bricks(int level) const { return bricks_[static_cast<std::size_t>(level)]; }
  std::uint64_t brickCount(int level) const;
  bool contains(const BrickKey& key) const;

  // The voxels the stored brick holds: [bB - 1, bB + B + 1) clamped to the
  // level (the clamped-away apron is replicated from the face voxels).
  VoxelBox readBox(const BrickKey& key) const;
  // Level-0 continuous voxel coordinates of the region the brick covers.
  glm::dvec3 lowerCorner(const BrickKey& key) const;
  glm::dvec3 upperCorner(const BrickKey& key) const;
  BrickKey parent(const BrickKey& key) const { return {key.level + 1, key.brick / 2}; }
  // The existing children at key.level - 1 (none at level 0).
  std::vector<BrickKey> children(const BrickKey& key) const;
  // The brick of `level` that covers level-0 brick cell `cell`.
  BrickKey ancestorOf(glm::ivec3 cell, int level) const { return {level, cell >> level}; }

 private:
  int brickSize_ = 32;
  std::vector<glm::ivec3> dims_;
  std::vector<glm::ivec3> bricks_;
};

// A brick as stored: (B + 2)^3 8-bit values (x fastest), apron included,
// and their range (stored units, 0..255).
struct StoredBrick {
  std::vector<std::uint8_t> voxels;
  std::uint8_t min = 0;
  std::uint8_t max = 0;
};

// Raw value -> stored 8-bit value: u8 volumes are stored as they are; other
// types are normalised over `window` (raw = min + stored / 255 * width).
struct StoredMapping {
  bool identity = true;
  double min = 0.0;
  double width = 255.0;
  static StoredMapping of(const Volume& shape);
  std::uint8_t store(double raw) const;
  double raw(double stored) const { return identity ? stored : min + stored / 255.0 * width; }
};

// Reads the brick through source.readBox and pads it to (B + 2)^3 with
// replicated face voxels. Throws what readBox throws, or Error if the source
// returns a box of the wrong size.
StoredBrick readStoredBrick(const MultiresSource& source, const BrickGrid& grid,
                            const BrickKey& key, const StoredMapping& mapping);

}  // namespace tessera::lod
