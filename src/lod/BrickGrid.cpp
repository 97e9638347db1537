#include "tessera/lod/BrickGrid.h"

#include <algorithm>
#include <cmath>

#include "tessera/core/Error.h"
#include "tessera/lod/LevelScale.h"

namespace tessera::lod {

namespace {

std::vector<glm::ivec3> factorsOfDims(const std::vector<glm::ivec3>& dims) {
  std::vector<LevelInfo> levels;
  for (glm::ivec3 d : dims) levels.push_back({.dims = d, .spacing = glm::vec3(0.0f), .chunk = {}});
  return levelFactors(levels, "brick grid");
}

}  // namespace

BrickGrid::BrickGrid(std::vector<glm::ivec3> levelDims, int brickSize)
    : BrickGrid(levelDims, factorsOfDims(levelDims), brickSize) {}

BrickGrid::BrickGrid(std::vector<glm::ivec3> levelDims, std::vector<glm::ivec3> levelFactors,
                     int brickSize)
    : brickSize_(brickSize),
      dims_(std::move(levelDims)),
      factors_(std::move(levelFactors)),
      scales_(levelScales(factors_)) {
  if (brickSize < 2) throw InputError("brick size must be >= 2, got " + std::to_string(brickSize));
  if (dims_.empty()) throw Error("a brick grid needs at least one level");
  if (factors_.size() != dims_.size()) throw Error("a brick grid needs one factor per level");
  for (glm::ivec3 d : dims_) bricks_.push_back((d + brickSize - 1) / brickSize);
}

BrickGrid BrickGrid::of(const MultiresSource& source, int brickSize) {
  std::vector<glm::ivec3> dims;
  for (int l = 0; l < source.levelCount(); ++l) dims.push_back(source.levelInfo(l).dims);
  return BrickGrid(std::move(dims), levelFactors(source), brickSize);
}

int BrickGrid::fanIn(int level) const {
  const glm::ivec3 f = factor(level);
  return f.x * f.y * f.z;
}

BrickKey BrickGrid::parent(const BrickKey& key) const {
  if (key.level + 1 >= levelCount()) return {key.level + 1, key.brick};
  return {key.level + 1, key.brick / factor(key.level + 1)};
}

std::uint64_t BrickGrid::brickCount(int level) const {
  const glm::ivec3 b = bricks(level);
  return static_cast<std::uint64_t>(b.x) * b.y * b.z;
}

bool BrickGrid::contains(const BrickKey& key) const {
  return key.level >= 0 && key.level < levelCount() &&
         glm::all(glm::greaterThanEqual(key.brick, glm::ivec3(0))) &&
         glm::all(glm::lessThan(key.brick, bricks(key.level)));
}

VoxelBox BrickGrid::readBox(const BrickKey& key) const {
  const glm::ivec3 d = dims(key.level);
  VoxelBox box;
  box.begin = glm::max(key.brick * brickSize_ - 1, glm::ivec3(0));
  box.end = glm::min(key.brick * brickSize_ + brickSize_ + 1, d);
  return box;
}

glm::dvec3 BrickGrid::lowerCorner(const BrickKey& key) const {
  return glm::dvec3(key.brick * brickSize_) * glm::dvec3(scale(key.level));
}

glm::dvec3 BrickGrid::upperCorner(const BrickKey& key) const {
  return glm::min(glm::dvec3((key.brick + 1) * brickSize_) * glm::dvec3(scale(key.level)),
                  glm::dvec3(dims(0)));
}

std::vector<BrickKey> BrickGrid::children(const BrickKey& key) const {
  std::vector<BrickKey> out;
  if (key.level == 0) return out;
  const glm::ivec3 f = factor(key.level);
  for (int dz = 0; dz < f.z; ++dz) {
    for (int dy = 0; dy < f.y; ++dy) {
      for (int dx = 0; dx < f.x; ++dx) {
        const BrickKey c{key.level - 1, key.brick * f + glm::ivec3(dx, dy, dz)};
        if (contains(c)) out.push_back(c);
      }
    }
  }
  return out;
}

StoredMapping StoredMapping::of(const Volume& shape) {
  StoredMapping m;
  switch (shape.type()) {
    case ScalarType::U8:
      return m;
    case ScalarType::U16:
      m.bits = 16;
      m.width = 65535.0;
      return m;
    case ScalarType::I16:
      m.bits = 16;
      m.min = -32768.0;
      m.width = 65535.0;
      return m;
    case ScalarType::F32:
      break;
  }
  const ValueRange r = shape.valueRange();
  m.bits = 16;
  m.exact = false;
  m.min = r.min;
  m.width = r.max > r.min ? r.max - r.min : 1.0;
  return m;
}

std::uint16_t StoredMapping::store(double raw) const {
  if (!std::isfinite(raw)) return 0;
  const double top = maxStored();
  const double s = exact ? raw - min : (raw - min) / width * top;
  return static_cast<std::uint16_t>(std::lround(std::clamp(s, 0.0, top)));
}

StoredBrick readStoredBrick(const MultiresSource& source, const BrickGrid& grid,
                            const BrickKey& key, const StoredMapping& mapping) {
  const VoxelBox box = grid.readBox(key);
  const Volume v = source.readBox(key.level, box);
  if (v.dims() != box.size()) {
    throw Error(source.describe() + ": readBox returned " + std::to_string(v.dims().x) + "x" +
                std::to_string(v.dims().y) + "x" + std::to_string(v.dims().z) + " voxels for a " +
                std::to_string(box.size().x) + "x" + std::to_string(box.size().y) + "x" +
                std::to_string(box.size().z) + " box");
  }
  const int n = grid.stored();
  const glm::ivec3 first = key.brick * grid.brickSize() - 1;  // level index of stored voxel 0
  const glm::ivec3 last = box.end - 1;
  StoredBrick out;
  out.bits = mapping.bits;
  const std::size_t bytesPer = mapping.bits == 8 ? 1 : 2;
  out.bytes.resize(grid.storedVoxels() * bytesPer);
  std::uint16_t lo = 65535, hi = 0;
  const bool u8 = v.type() == ScalarType::U8 && mapping.bits == 8 && mapping.exact;
  const std::uint8_t* src = u8 ? v.dataAs<std::uint8_t>() : nullptr;
  std::uint8_t* dst = out.bytes.data();
  for (int z = 0; z < n; ++z) {
    const int sz = std::clamp(first.z + z, box.begin.z, last.z) - box.begin.z;
    for (int y = 0; y < n; ++y) {
      const int sy = std::clamp(first.y + y, box.begin.y, last.y) - box.begin.y;
      for (int x = 0; x < n; ++x) {
        const int sx = std::clamp(first.x + x, box.begin.x, last.x) - box.begin.x;
        const std::size_t at = v.index(sx, sy, sz);
        const std::uint16_t s = u8 ? src[at] : mapping.store(v.valueAtIndex(at));
        if (bytesPer == 1) {
          *dst++ = static_cast<std::uint8_t>(s);
        } else {
          *dst++ = static_cast<std::uint8_t>(s & 0xff);
          *dst++ = static_cast<std::uint8_t>(s >> 8);
        }
        lo = std::min(lo, s);
        hi = std::max(hi, s);
      }
    }
  }
  out.min = lo;
  out.max = hi;
  return out;
}

}  // namespace tessera::lod
