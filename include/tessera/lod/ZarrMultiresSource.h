#pragma once
// An OME-Zarr store (io::ZarrStore: a folder or an HTTP(S) URL) as the
// pyramid the bricked layout and the streaming scheduler read: each level
// is one of the store's datasets, read one box at a time, only the chunks
// the box touches.
#include <algorithm>
#include <memory>
#include <string>

#include "tessera/io/ZarrStore.h"
#include "tessera/lod/MultiresSource.h"

namespace tessera::lod {

class ZarrMultiresSource final : public MultiresSource {
 public:
  explicit ZarrMultiresSource(std::shared_ptr<const ZarrStore> store);
  // Opens a folder or URL (see io/ZarrStore.h), with a time point and
  // channel, keeping decodedChunkBudget() of decoded chunks. Native only: the browser reads stores
  // through the page's fetch() (frontends/web/src/ZarrFetchStorage.h).
  static std::unique_ptr<ZarrMultiresSource> open(const std::string& spec,
                                                  ZarrSelection selection = {});

  const Volume& shape() const override { return store_->shape(); }
  int levelCount() const override { return store_->levelCount(); }
  LevelInfo levelInfo(int level) const override;
  Volume readBox(int level, const VoxelBox& box) const override;
  std::string describe() const override { return store_->describe(); }
  // As the store's multiscales metadata says ("type": "mean", which
  // `tessera convert` writes); a store that does not say is not trusted.
  bool meanPyramid() const override { return store_->reduction() == "mean"; }
  // The decoded chunks' budget the store was opened with (0 when it keeps
  // none); a limit lowers it, never above that.
  std::uint64_t decodedCacheWanted() const override { return wanted_; }
  void limitDecodedCache(std::uint64_t bytes) const override {
    store_->limitDecodedChunks(std::min(bytes, wanted_));
  }
  std::uint64_t decodedCachePeakBytes() const override { return store_->chunkStats().peakBytes; }

  const ZarrStore& store() const { return *store_; }
  // Time point `time` of the same store (its selection's channel), read
  // from that time point's chunks only, over the same storage and with a
  // decoded-chunk cache of its own of the same budget: the pyramid of one
  // time point that a streamed series plays (session/StreamedSeries.h).
  // InputError (naming --time and the store) for a time point it lacks.
  std::shared_ptr<ZarrMultiresSource> atTime(int time) const;

  // The decoded chunks kept while bricks are read: every chunk of the store
  // (a refinement reads each once, however many bricks a chunk holds, in
  // whatever order the view wants them) when that is at most an eighth of
  // the host budget; else that eighth, least recently used out, and the
  // streamer's queue, grouped by chunk, keeps the chunks it needs together.
  static constexpr std::uint64_t kDecodedChunkShare = 8;
  static std::uint64_t decodedChunkBudget(const ZarrStore& store, std::uint64_t hostBudget);

 private:
  std::shared_ptr<const ZarrStore> store_;
  std::uint64_t wanted_ = 0;
};

}  // namespace tessera::lod
