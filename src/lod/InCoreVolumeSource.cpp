#include "tessera/lod/InCoreVolumeSource.h"

#include <utility>

#include "tessera/core/Error.h"
#include "tessera/lod/Downsample.h"

namespace tessera::lod {

InCoreVolumeSource::InCoreVolumeSource(Volume volume)
    : volume_(std::make_shared<Volume>(std::move(volume))) {}

InCoreVolumeSource::InCoreVolumeSource(std::shared_ptr<Volume> volume)
    : volume_(std::move(volume)) {
  if (!volume_) throw Error("InCoreVolumeSource: no volume");
}

std::shared_ptr<Volume> InCoreVolumeSource::level(glm::ivec3 factor) const {
  if (factor == glm::ivec3(1)) return volume_;
  return std::make_shared<Volume>(downsample(*volume_, factor));
}

}  // namespace tessera::lod
