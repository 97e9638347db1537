#include "tessera/io/ZarrCachedStorage.h"

namespace tessera {

namespace {
constexpr std::uint64_t kEntryOverhead = 64;  // the key, list and map nodes, roughly
}  // namespace

CachedStorage::CachedStorage(std::shared_ptr<const ZarrStorage> inner, std::uint64_t budgetBytes)
    : inner_(std::move(inner)), budget_(budgetBytes) {}

std::uint64_t CachedStorage::cost(const Entry& e) const {
  return kEntryOverhead + (e.bytes ? e.bytes->size() : 0);
}

std::optional<std::vector<std::byte>> CachedStorage::get(const std::string& key,
                                                         std::uint64_t maxBytes) const {
  {
    const std::lock_guard lock(mutex_);
    const auto it = entries_.find(key);
    if (it != entries_.end() && (!it->second.bytes || it->second.bytes->size() <= maxBytes)) {
      uses_.splice(uses_.begin(), uses_, it->second.use);
      return it->second.bytes;
    }
  }
  // Read outside the lock: other keys are read in parallel meanwhile.
  auto bytes = inner_->get(key, maxBytes);
  keep(key, bytes, bytes ? bytes->size() : 0);
  return bytes;
}

std::optional<ZarrRange> CachedStorage::getRange(const std::string& key, std::int64_t offset,
                                                 std::uint64_t length,
                                                 std::uint64_t maxWhole) const {
  const std::string rangeKey = key + "#" + std::to_string(offset) + "+" + std::to_string(length);
  {
    const std::lock_guard lock(mutex_);
    const auto it = entries_.find(rangeKey);
    if (it != entries_.end()) {
      uses_.splice(uses_.begin(), uses_, it->second.use);
      if (!it->second.bytes) return std::nullopt;
      return ZarrRange{*it->second.bytes, it->second.total};
    }
  }
  auto r = inner_->getRange(key, offset, length, maxWhole);
  keep(rangeKey, r ? std::optional(r->bytes) : std::nullopt, r ? r->total : 0);
  return r;
}

void CachedStorage::keep(const std::string& key, std::optional<std::vector<std::byte>> bytes,
                         std::uint64_t total) const {
  const std::lock_guard lock(mutex_);
  if (entries_.count(key) != 0) return;  // another thread stored it first
  uses_.push_front(key);
  Entry& e = entries_[key];
  e.bytes = std::move(bytes);
  e.total = total;
  e.use = uses_.begin();
  held_ += cost(e);
  while (held_ > budget_ && !uses_.empty()) {
    const auto victim = entries_.find(uses_.back());
    held_ -= cost(victim->second);
    entries_.erase(victim);
    uses_.pop_back();
  }
}

void CachedStorage::forget(const std::string& key) const {
  const std::lock_guard lock(mutex_);
  // The key and every range of it (a damaged shard's inner chunks).
  for (auto it = entries_.begin(); it != entries_.end();) {
    if (it->first == key || it->first.rfind(key + "#", 0) == 0) {
      held_ -= cost(it->second);
      uses_.erase(it->second.use);
      it = entries_.erase(it);
    } else {
      ++it;
    }
  }
}

}  // namespace tessera
