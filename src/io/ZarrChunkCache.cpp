#include "tessera/io/ZarrChunkCache.h"

#include <algorithm>

namespace tessera {

namespace {
// A missing chunk (fill_value) costs its key, list and map nodes, roughly;
// a stored one its bytes (its nodes are under 0.01% of any real chunk), so
// that a budget of every chunk's bytes holds every chunk.
constexpr std::uint64_t kEntryOverhead = 96;
std::uint64_t cost(const ZarrChunkCache::Chunk& chunk) {
  return std::max<std::uint64_t>(kEntryOverhead, chunk ? chunk->size() : 0);
}
}  // namespace

ZarrChunkCache::Chunk ZarrChunkCache::get(const std::string& key, const Decode& decode) {
  std::shared_ptr<Slot> slot;
  {
    std::unique_lock lock(mutex_);
    const auto it = entries_.find(key);
    if (it != entries_.end()) {
      slot = it->second.slot;
      if (slot->ready) {
        ++stats_.hits;
        uses_.splice(uses_.begin(), uses_, it->second.use);
        return slot->chunk;
      }
      // Another thread is decoding it: its result (or error) is ours.
      ++stats_.waits;
      decoded_.wait(lock, [&] { return slot->ready; });
      if (slot->error) std::rethrow_exception(slot->error);
      return slot->chunk;
    }
    slot = std::make_shared<Slot>();
    entries_.emplace(key, Entry{.slot = slot, .use = {}, .bytes = 0});
    ++stats_.decodes;
  }
  // Fetched and decoded outside the lock: other chunks are read meanwhile.
  Chunk chunk;
  try {
    chunk = decode();
  } catch (...) {
    finish(key, slot, nullptr, std::current_exception());
    throw;
  }
  finish(key, slot, chunk, nullptr);
  return chunk;
}

void ZarrChunkCache::finish(const std::string& key, const std::shared_ptr<Slot>& slot, Chunk chunk,
                            std::exception_ptr error) {
  {
    const std::lock_guard lock(mutex_);
    slot->ready = true;
    slot->chunk = chunk;
    slot->error = error;
    const auto it = entries_.find(key);
    if (error) {
      entries_.erase(it);  // not remembered: the next read tries again
    } else {
      it->second.bytes = cost(chunk);
      uses_.push_front(key);
      it->second.use = uses_.begin();
      stats_.heldBytes += it->second.bytes;
      evictOver();
      stats_.peakBytes = std::max(stats_.peakBytes, stats_.heldBytes);
    }
  }
  decoded_.notify_all();
}

void ZarrChunkCache::evictOver() {
  while (stats_.heldBytes > budget_ && !uses_.empty()) {
    const auto victim = entries_.find(uses_.back());
    stats_.heldBytes -= victim->second.bytes;
    entries_.erase(victim);
    uses_.pop_back();
  }
}

std::uint64_t ZarrChunkCache::budgetBytes() const {
  const std::lock_guard lock(mutex_);
  return budget_;
}

void ZarrChunkCache::setBudget(std::uint64_t bytes) {
  const std::lock_guard lock(mutex_);
  budget_ = bytes;
  evictOver();
}

ZarrChunkCacheStats ZarrChunkCache::stats() const {
  const std::lock_guard lock(mutex_);
  return stats_;
}

}  // namespace tessera
