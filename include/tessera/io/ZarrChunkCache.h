#pragma once
// Decoded Zarr chunks, kept least recently used first out within a byte
// budget, so that a chunk is fetched and decoded once however many boxes
// read from it. The bricks layout reads a store one small box (a brick and
// its apron) at a time: with chunks much larger than bricks (microscopy's
// 32x512x512) every brick of a chunk decoded the whole chunk again. A chunk
// being decoded is shared: a second thread that wants it waits for the
// first (and gets its result or its error) instead of decoding it too.
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

namespace tessera {

struct ZarrChunkCacheStats {
  std::uint64_t decodes = 0;  // chunks fetched and decoded (each decode call)
  std::uint64_t hits = 0;     // chunks found decoded already
  std::uint64_t waits = 0;    // chunks another thread was decoding (waited for)
  std::uint64_t heldBytes = 0;
  std::uint64_t peakBytes = 0;
};

class ZarrChunkCache {
 public:
  // A decoded chunk; null for a chunk that is not stored (fill_value).
  using Chunk = std::shared_ptr<const std::vector<std::byte>>;
  // Fetches and decodes one chunk; may throw.
  using Decode = std::function<Chunk()>;

  // Holds decoded chunks up to `budgetBytes`; a chunk larger than that is
  // shared while it is being decoded, then dropped (callers hold theirs).
  explicit ZarrChunkCache(std::uint64_t budgetBytes) : budget_(budgetBytes) {}

  // The chunk under `key`: cached, or decoded by the thread decoding it
  // now (this one waits; its error is rethrown here), or by `decode` on
  // this thread. A failed decode is not remembered: the next get tries
  // again. Thread-safe.
  Chunk get(const std::string& key, const Decode& decode);

  std::uint64_t budgetBytes() const;
  // A new budget from now on; chunks over it are let go at once.
  void setBudget(std::uint64_t bytes);
  ZarrChunkCacheStats stats() const;

 private:
  struct Slot {
    bool ready = false;
    Chunk chunk;
    std::exception_ptr error;
  };
  struct Entry {
    std::shared_ptr<Slot> slot;
    std::list<std::string>::iterator use;  // valid once ready
    std::uint64_t bytes = 0;
  };
  void finish(const std::string& key, const std::shared_ptr<Slot>& slot, Chunk chunk,
              std::exception_ptr error);
  void evictOver();  // lock held

  std::uint64_t budget_;
  mutable std::mutex mutex_;
  std::condition_variable decoded_;
  std::list<std::string> uses_;  // ready entries, most recent first
  std::unordered_map<std::string, Entry> entries_;
  ZarrChunkCacheStats stats_;
};

}  // namespace tessera
