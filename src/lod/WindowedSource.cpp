#include "tessera/lod/WindowedSource.h"

#include "tessera/core/Error.h"

namespace tessera::lod {

WindowedSource::WindowedSource(std::shared_ptr<const MultiresSource> inner, ValueRange window)
    : inner_(std::move(inner)) {
  if (!inner_) throw Error("WindowedSource: no source");
  shape_ = inner_->shape();
  shape_.setWindow(window);
}

Volume WindowedSource::readBox(int level, const VoxelBox& box) const {
  Volume v = inner_->readBox(level, box);
  v.setWindow(shape_.window());
  return v;
}

}  // namespace tessera::lod
