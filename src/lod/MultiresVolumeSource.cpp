#include "tessera/lod/MultiresVolumeSource.h"

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/lod/Downsample.h"

namespace tessera::lod {

MultiresVolumeSource::MultiresVolumeSource(std::shared_ptr<const MultiresSource> source)
    : source_(std::move(source)) {
  if (!source_) throw Error("MultiresVolumeSource: no source");
}

std::shared_ptr<Volume> MultiresVolumeSource::level(glm::ivec3 factor) const {
  int l = 0;
  for (int k = 1; k < source_->levelCount() && k < 30; ++k) {
    if (factor == glm::ivec3(1 << k)) l = k;
  }
  const glm::ivec3 d = source_->levelInfo(l).dims;
  const std::uint64_t bytes =
      static_cast<std::uint64_t>(d.x) * d.y * d.z * bytesPerVoxel(source_->shape().type());
  HostBudget::global().check(bytes, "level " + std::to_string(l) + " of " + source_->describe());
  auto v = std::make_shared<Volume>(source_->readBox(l, {glm::ivec3(0), d}));
  if (factor == glm::ivec3(1 << l)) return v;
  return std::make_shared<Volume>(downsample(*v, factor));  // l is 0 here
}

}  // namespace tessera::lod
