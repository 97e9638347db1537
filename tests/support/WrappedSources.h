#pragma once
// Multiresolution sources that wrap another one to make its reads fail or
// arrive late, for the streamer's retries and the layout's fallbacks.
#include <memory>
#include <string>
#include <utility>

#include "tessera/core/Error.h"
#include "tessera/lod/MultiresSource.h"

namespace tessera::test {

// Reads `inner` as it is; a wrapper overrides what it changes. Bricks are
// told apart by their column, (box.begin.x + 1) / brick: the streamer's boxes
// start one voxel of apron before the brick.
class WrappedSource : public lod::MultiresSource {
 public:
  WrappedSource(std::shared_ptr<const lod::MultiresSource> inner, int brick)
      : inner_(std::move(inner)), brick_(brick) {}
  const Volume& shape() const override { return inner_->shape(); }
  int levelCount() const override { return inner_->levelCount(); }
  lod::LevelInfo levelInfo(int level) const override { return inner_->levelInfo(level); }
  Volume readBox(int level, const lod::VoxelBox& box) const override {
    return inner_->readBox(level, box);
  }
  std::string describe() const override { return inner_->describe(); }

 protected:
  int column(const lod::VoxelBox& box) const { return (box.begin.x + 1) / brick_; }

 private:
  std::shared_ptr<const lod::MultiresSource> inner_;
  int brick_;
};

// Level-0 reads fail for every brick in an odd column, the way an
// unreachable remote chunk fails.
class FlakySource final : public WrappedSource {
 public:
  using WrappedSource::WrappedSource;
  Volume readBox(int level, const lod::VoxelBox& box) const override {
    if (level == 0 && column(box) % 2 == 1) {
      throw Error("flaky: chunk 0/" + std::to_string(column(box)) + " unreachable (HTTP 500)");
    }
    return WrappedSource::readBox(level, box);
  }
  std::string describe() const override { return "flaky " + WrappedSource::describe(); }
};

}  // namespace tessera::test
