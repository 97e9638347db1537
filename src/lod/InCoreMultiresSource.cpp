#include "tessera/lod/InCoreMultiresSource.h"

#include <algorithm>
#include <cstring>

#include "tessera/core/Error.h"
#include "tessera/lod/Downsample.h"

namespace tessera::lod {

namespace {
std::string boxText(const VoxelBox& b) {
  auto v = [](glm::ivec3 p) {
    return std::to_string(p.x) + "," + std::to_string(p.y) + "," + std::to_string(p.z);
  };
  return "[" + v(b.begin) + " .. " + v(b.end) + ")";
}
}  // namespace

std::vector<glm::ivec3> pyramidDims(glm::ivec3 dims, int coarsestSide, glm::ivec3 factor) {
  if (glm::any(glm::lessThan(factor, glm::ivec3(1)))) {
    throw InputError("pyramid factors must be >= 1");
  }
  std::vector<glm::ivec3> out{dims};
  auto longestReduced = [&](glm::ivec3 d) {
    int m = 0;
    for (int a = 0; a < 3; ++a) m = factor[a] > 1 ? std::max(m, d[a]) : m;
    return m;
  };
  while (longestReduced(out.back()) > std::max(1, coarsestSide)) {
    out.push_back((out.back() + factor - 1) / factor);
  }
  return out;
}

Volume copyBox(const Volume& volume, const VoxelBox& box) {
  const glm::ivec3 d = volume.dims();
  if (box.count() == 0 || glm::any(glm::lessThan(box.begin, glm::ivec3(0))) ||
      glm::any(glm::greaterThan(box.end, d))) {
    throw Error("box " + boxText(box) + " is empty or outside the volume's " + std::to_string(d.x) +
                "x" + std::to_string(d.y) + "x" + std::to_string(d.z) + " voxels");
  }
  const glm::ivec3 s = box.size();
  Volume out = Volume::allocate(s, volume.type(), "box of " + volume.description());
  out.setSpacing(volume.spacing());
  out.setDirection(volume.direction());
  out.setOrigin(volume.worldOf(glm::dvec3(box.begin)));
  if (volume.hasWindow()) out.setWindow(volume.window());
  const std::size_t bpv = bytesPerVoxel(volume.type());
  const std::size_t row = static_cast<std::size_t>(s.x) * bpv;
  const std::byte* src = volume.bytes().data();
  std::byte* dst = out.bytes().data();
  for (int z = 0; z < s.z; ++z) {
    for (int y = 0; y < s.y; ++y) {
      std::memcpy(dst + out.index(0, y, z) * bpv,
                  src + volume.index(box.begin.x, box.begin.y + y, box.begin.z + z) * bpv, row);
    }
  }
  return out;
}

InCoreMultiresSource::InCoreMultiresSource(std::shared_ptr<const Volume> volume, int coarsestSide,
                                           glm::ivec3 factor) {
  if (!volume || !volume->hasData()) throw Error("InCoreMultiresSource: no voxels");
  levels_.push_back(volume);
  const std::vector<glm::ivec3> dims = pyramidDims(volume->dims(), coarsestSide, factor);
  for (std::size_t l = 1; l < dims.size(); ++l) {
    levels_.push_back(std::make_shared<const Volume>(downsample(*levels_.back(), factor)));
  }
  shape_ = Volume::shapeOnly(volume->dims(), volume->type());
  shape_.setSpacing(volume->spacing());
  shape_.setDirection(volume->direction());
  shape_.setOrigin(volume->origin());
  shape_.setGeometrySource(volume->geometrySource());
  shape_.setValueRange(volume->valueRange());
  shape_.setWindow(volume->window());
  shape_.setDescription(volume->description());
  shape_.setModality(volume->modality());
}

LevelInfo InCoreMultiresSource::levelInfo(int level) const {
  const Volume& v = this->level(level);
  return {.dims = v.dims(), .spacing = glm::vec3(v.spacing()), .chunk = glm::ivec3(0)};
}

const Volume& InCoreMultiresSource::level(int level) const {
  if (level < 0 || level >= levelCount()) {
    throw Error("level " + std::to_string(level) + " of a pyramid of " +
                std::to_string(levelCount()));
  }
  return *levels_[static_cast<std::size_t>(level)];
}

Volume InCoreMultiresSource::readBox(int level, const VoxelBox& box) const {
  return copyBox(this->level(level), box);
}

std::string InCoreMultiresSource::describe() const {
  return "in-core pyramid of " + std::to_string(levelCount()) + " levels (" + shape_.description() +
         ")";
}

}  // namespace tessera::lod
