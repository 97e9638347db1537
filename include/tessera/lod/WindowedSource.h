#pragma once
// A MultiresSource seen through another value window: the user's window
// (render --window, the viewers' window) over a streamed volume. Its shape()
// and every box it reads carry the window; the voxels, levels and storage
// are the inner source's. The bricks layout classifies bricks by this
// window and the renderer maps values through it, as for an in-core volume.
#include <memory>

#include "tessera/lod/MultiresSource.h"

namespace tessera::lod {

class WindowedSource final : public MultiresSource {
 public:
  // InputError if the window is empty or not finite.
  WindowedSource(std::shared_ptr<const MultiresSource> inner, ValueRange window);

  const Volume& shape() const override { return shape_; }
  int levelCount() const override { return inner_->levelCount(); }
  LevelInfo levelInfo(int level) const override { return inner_->levelInfo(level); }
  Volume readBox(int level, const VoxelBox& box) const override;
  bool prefetch(int level, const VoxelBox& box) const override {
    return inner_->prefetch(level, box);
  }
  bool meanPyramid() const override { return inner_->meanPyramid(); }
  std::uint64_t decodedCacheWanted() const override { return inner_->decodedCacheWanted(); }
  void limitDecodedCache(std::uint64_t bytes) const override { inner_->limitDecodedCache(bytes); }
  std::uint64_t decodedCachePeakBytes() const override { return inner_->decodedCachePeakBytes(); }
  std::string describe() const override { return inner_->describe(); }

  const std::shared_ptr<const MultiresSource>& inner() const { return inner_; }

 private:
  std::shared_ptr<const MultiresSource> inner_;
  Volume shape_;
};

}  // namespace tessera::lod
