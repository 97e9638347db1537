#pragma once
// A ZarrStorage that keeps the stored (compressed) bytes of recently read
// keys, least recently used first out, within a byte budget. The bricks
// layout reads each brick with a one-voxel apron, so a brick's box touches
// the chunks around it: without this every neighbour chunk was fetched
// again for every brick beside it (8 times each for a 2x2x2-chunk level
// over HTTP). Missing keys (404s) are remembered too.
#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

#include "tessera/io/ZarrStorage.h"

namespace tessera {

class CachedStorage final : public ZarrStorage {
 public:
  CachedStorage(std::shared_ptr<const ZarrStorage> inner, std::uint64_t budgetBytes);

  std::optional<std::vector<std::byte>> get(const std::string& key,
                                            std::uint64_t maxBytes) const override;
  // Ranges are kept as their own entries ("key#offset+length"), so a
  // shard's index and inner chunks are fetched once.
  std::optional<ZarrRange> getRange(const std::string& key, std::int64_t offset,
                                    std::uint64_t length, std::uint64_t maxWhole) const override;
  void forget(const std::string& key) const override;
  std::string locate(const std::string& key) const override { return inner_->locate(key); }
  int refetches() const override { return inner_->refetches(); }
  bool decodesChunks(ZarrCompressor c) const override { return inner_->decodesChunks(c); }
  int parallelism() const override { return inner_->parallelism(); }
  std::string describe() const override { return inner_->describe(); }

  const ZarrStorage& inner() const { return *inner_; }

 private:
  struct Entry {
    std::optional<std::vector<std::byte>> bytes;
    std::uint64_t total = 0;  // a range's whole value
    std::list<std::string>::iterator use;
  };
  std::uint64_t cost(const Entry& e) const;
  void keep(const std::string& key, std::optional<std::vector<std::byte>> bytes,
            std::uint64_t total) const;

  std::shared_ptr<const ZarrStorage> inner_;
  std::uint64_t budget_;
  mutable std::mutex mutex_;
  mutable std::uint64_t held_ = 0;
  mutable std::list<std::string> uses_;  // most recent first
  mutable std::unordered_map<std::string, Entry> entries_;
};

}  // namespace tessera
