#pragma once
// Multiresolution sources that wrap another one to make its reads fail or
// arrive late, for the streamer's retries and the layout's fallbacks.
#include <chrono>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "tessera/core/Error.h"
#include "tessera/lod/BrickGrid.h"
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

// Reads of the `dead` bricks (told by their read box in `grid`) always
// throw, after `failAfterMs`: a chunk whose server answers 500 (or never)
// and whose storage gives up only after its own retries. Each error names
// the brick as a URL would ("dead://store/LEVEL/X/Y/Z: HTTP 500"), or, with
// `oneUrl`, all name that one (one chunk under several bricks' aprons).
// Counts the reads of each dead brick.
class DeadBricksSource final : public WrappedSource {
 public:
  DeadBricksSource(std::shared_ptr<const lod::MultiresSource> inner, const lod::BrickGrid& grid,
                   std::vector<lod::BrickKey> dead, double failAfterMs, std::string oneUrl = "")
      : WrappedSource(std::move(inner), grid.brickSize()),
        dead_(std::move(dead)),
        failAfterMs_(failAfterMs),
        oneUrl_(std::move(oneUrl)),
        reads_(dead_.size(), 0) {
    for (const lod::BrickKey& k : dead_) boxes_.push_back(grid.readBox(k));
  }
  Volume readBox(int level, const lod::VoxelBox& box) const override {
    for (std::size_t i = 0; i < dead_.size(); ++i) {
      if (level != dead_[i].level || box.begin != boxes_[i].begin || box.end != boxes_[i].end) {
        continue;
      }
      {
        const std::lock_guard lock(mutex_);
        ++reads_[i];
      }
      std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(failAfterMs_));
      throw Error((oneUrl_.empty() ? url(dead_[i]) : oneUrl_) + ": HTTP 500 (test double)");
    }
    return WrappedSource::readBox(level, box);
  }
  std::string describe() const override { return "dead-bricks " + WrappedSource::describe(); }
  static std::string url(const lod::BrickKey& k) {
    return "dead://store/" + std::to_string(k.level) + "/" + std::to_string(k.brick.x) + "/" +
           std::to_string(k.brick.y) + "/" + std::to_string(k.brick.z);
  }
  int reads(std::size_t i) const {
    const std::lock_guard lock(mutex_);
    return reads_[i];
  }

 private:
  std::vector<lod::BrickKey> dead_;
  std::vector<lod::VoxelBox> boxes_;
  double failAfterMs_;
  std::string oneUrl_;
  mutable std::mutex mutex_;
  mutable std::vector<int> reads_;
};

}  // namespace tessera::test
