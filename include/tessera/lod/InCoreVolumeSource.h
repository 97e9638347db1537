#pragma once
// A volume held in host memory as a VolumeSource: what every reader and
// generator gives today. Reductions are made on request by lod::downsample.
#include <memory>

#include "tessera/lod/VolumeSource.h"

namespace tessera::lod {

class InCoreVolumeSource final : public VolumeSource {
 public:
  explicit InCoreVolumeSource(Volume volume);
  explicit InCoreVolumeSource(std::shared_ptr<Volume> volume);

  const Volume& shape() const override { return *volume_; }
  std::shared_ptr<Volume> level(glm::ivec3 factor) const override;

  // The full-resolution volume (its window may be changed).
  Volume& volume() { return *volume_; }
  const Volume& volume() const { return *volume_; }

 private:
  std::shared_ptr<Volume> volume_;
};

}  // namespace tessera::lod
