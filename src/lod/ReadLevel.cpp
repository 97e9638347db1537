#include "tessera/lod/ReadLevel.h"

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/lod/LevelScale.h"

namespace tessera::lod {

namespace {

void checkLevel(const MultiresSource& source, int level) {
  if (level < 0 || level >= source.levelCount()) {
    throw InputError("level " + std::to_string(level) + " of " + source.describe() +
                     ": the pyramid has levels 0.." + std::to_string(source.levelCount() - 1) +
                     " (0 = the finest)");
  }
}

}  // namespace

std::uint64_t levelBytes(const MultiresSource& source, int level) {
  checkLevel(source, level);
  const glm::ivec3 d = source.levelInfo(level).dims;
  return VoxelBox{glm::ivec3(0), d}.count() * bytesPerVoxel(source.shape().type());
}

std::string describeLevel(const MultiresSource& source, int level) {
  const glm::ivec3 d = source.levelInfo(level).dims;
  return "level " + std::to_string(level) + " (" + std::to_string(d.x) + "x" + std::to_string(d.y) +
         "x" + std::to_string(d.z) + " " + std::string(scalarTypeName(source.shape().type())) +
         ", " + formatBytes(levelBytes(source, level)) + ")";
}

Volume readLevel(const MultiresSource& source, int level) {
  checkLevel(source, level);
  HostBudget::global().check(levelBytes(source, level),
                             describeLevel(source, level) + " of " + source.describe());
  const Volume& shape = source.shape();
  Volume out = source.readBox(level, {glm::ivec3(0), source.levelInfo(level).dims});
  const glm::dvec3 scale(levelScale(source, level));
  out.setSpacing(shape.spacing() * scale);
  out.setDirection(shape.direction());
  out.setOrigin(shape.worldOf(0.5 * (scale - 1.0)));
  out.setGeometrySource(shape.geometrySource());
  if (shape.hasWindow()) out.setWindow(shape.window());
  out.setModality(shape.modality());
  out.setDescription(shape.description() + " level " + std::to_string(level));
  return out;
}

}  // namespace tessera::lod
