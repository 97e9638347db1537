#pragma once
// A MultiresSource (a chunked store, a generated volume) as a VolumeSource:
// the planner sees its shape and that it is streamed; the bricks layout reads
// it box by box; an in-core layout, when the plan chooses one, gets a whole
// level read into host memory (checked against the host budget first).
#include <memory>

#include "tessera/lod/VolumeSource.h"

namespace tessera::lod {

class MultiresVolumeSource final : public VolumeSource {
 public:
  explicit MultiresVolumeSource(std::shared_ptr<const MultiresSource> source);

  const Volume& shape() const override { return source_->shape(); }
  // The pyramid level when `factor` is 2^l on every axis, else level 0
  // reduced by lod::downsample.
  std::shared_ptr<Volume> level(glm::ivec3 factor) const override;
  std::shared_ptr<const MultiresSource> multires() const override { return source_; }

 private:
  std::shared_ptr<const MultiresSource> source_;
};

}  // namespace tessera::lod
