#pragma once
// Bricks of a multiresolution source (Schultz 2016 §7.3; DESIGN.md "Large
// data"): level l is cut into bricks of B^3 voxels (the last brick along an
// axis may be partial); each brick is stored with a one-voxel apron of its
// neighbours' voxels (replicated at the volume's faces), (B + 2)^3 voxels in
// all, so trilinear interpolation anywhere inside the brick reads only the
// brick and the bricked volume shows no seams. Each level keeps or divides
// each axis of the one before by its own factor f_l (lod/LevelScale.h: 2 per
// axis in a factor-2 pyramid, (1, 2, 2) where z is kept), so brick (l, b)
// covers level-0 voxels [b B s_l, (b + 1) B s_l) per axis, s_l the product of
// the factors up to l; its parent is (l + 1, b / f_(l+1)).
#include <cstddef>
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
  // The factors from the dims alone (lod::levelFactors; 2 where an axis of
  // one voxel leaves it open).
  BrickGrid(std::vector<glm::ivec3> levelDims, int brickSize);
  // `levelFactors`: per level, what lod::levelFactors gives (level 0's is 1).
  BrickGrid(std::vector<glm::ivec3> levelDims, std::vector<glm::ivec3> levelFactors, int brickSize);
  // The source's level dims and factors (InputError as lod::levelFactors).
  static BrickGrid of(const MultiresSource& source, int brickSize);

  int brickSize() const { return brickSize_; }
  int stored() const { return brickSize_ + 2; }  // with the apron
  std::uint64_t storedVoxels() const {
    return static_cast<std::uint64_t>(stored()) * stored() * stored();
  }
  int levelCount() const { return static_cast<int>(dims_.size()); }
  glm::ivec3 dims(int level) const { return dims_[static_cast<std::size_t>(level)]; }
  glm::ivec3 bricks(int level) const { return bricks_[static_cast<std::size_t>(level)]; }
  // Level-(l - 1) voxels per level-l voxel along each axis (1 at level 0).
  glm::ivec3 factor(int level) const { return factors_[static_cast<std::size_t>(level)]; }
  // Level-0 voxels per level-l voxel along each axis.
  glm::ivec3 scale(int level) const { return scales_[static_cast<std::size_t>(level)]; }
  // The level-(l - 1) voxels a level-l voxel averages in a mean pyramid (8
  // for a factor of 2 on every axis, 4 for (1, 2, 2)); 1 at level 0.
  int fanIn(int level) const;
  std::uint64_t brickCount(int level) const;
  bool contains(const BrickKey& key) const;

  // The voxels the stored brick holds: [bB - 1, bB + B + 1) clamped to the
  // level (the clamped-away apron is replicated from the face voxels).
  VoxelBox readBox(const BrickKey& key) const;
  // Level-0 continuous voxel coordinates of the region the brick covers.
  glm::dvec3 lowerCorner(const BrickKey& key) const;
  glm::dvec3 upperCorner(const BrickKey& key) const;
  // Past the coarsest level: {levelCount(), brick}, which contains() refuses.
  BrickKey parent(const BrickKey& key) const;
  // The existing children at key.level - 1 (none at level 0).
  std::vector<BrickKey> children(const BrickKey& key) const;
  // The brick of `level` that covers level-0 brick cell `cell`.
  BrickKey ancestorOf(glm::ivec3 cell, int level) const { return {level, cell / scale(level)}; }

 private:
  int brickSize_ = 32;
  std::vector<glm::ivec3> dims_;
  std::vector<glm::ivec3> bricks_;
  std::vector<glm::ivec3> factors_;
  std::vector<glm::ivec3> scales_;
};

// How raw values are stored in bricks: in 8 bits for u8 volumes (as they
// are), in 16 bits otherwise. u16 and i16 are stored exactly (raw - min of
// the type); f32 is normalised over the volume's value range (a step of
// width / 65535), so any window, however narrow, keeps its grey levels.
// raw = min + stored / maxStored() * width.
struct StoredMapping {
  int bits = 8;          // 8 or 16 bits per stored value
  bool exact = true;     // every raw value is stored without rounding
  double min = 0.0;      // the raw value of stored 0
  double width = 255.0;  // the raw width stored maxStored() spans
  static StoredMapping of(const Volume& shape);
  int maxStored() const { return bits == 8 ? 255 : 65535; }
  std::uint16_t store(double raw) const;
  double raw(double stored) const { return min + stored / maxStored() * width; }
};

// A brick as stored: (B + 2)^3 values (x fastest), apron included, of
// mapping.bits each (16-bit values little-endian, as GL takes them: R16
// reads one unsigned short, RG8 and LUMINANCE_ALPHA the low byte in their
// first channel and the high byte in their second), and their range in
// stored units.
struct StoredBrick {
  int bits = 8;
  std::vector<std::uint8_t> bytes;
  std::uint16_t min = 0;
  std::uint16_t max = 0;
  std::size_t count() const { return bits == 8 ? bytes.size() : bytes.size() / 2; }
  std::uint16_t value(std::size_t i) const {
    return bits == 8 ? bytes[i]
                     : static_cast<std::uint16_t>(bytes[2 * i] | (bytes[2 * i + 1] << 8));
  }
};

// Reads the brick through source.readBox and pads it to (B + 2)^3 with
// replicated face voxels. Throws what readBox throws, or Error if the source
// returns a box of the wrong size.
StoredBrick readStoredBrick(const MultiresSource& source, const BrickGrid& grid,
                            const BrickKey& key, const StoredMapping& mapping);

}  // namespace tessera::lod
