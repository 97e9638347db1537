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
  const std::lock_guard lock(mutex_);
  if (entries_.count(key) != 0) return bytes;  // another thread stored it first
  uses_.push_front(key);
  Entry& e = entries_[key];
  e.bytes = bytes;
  e.use = uses_.begin();
  held_ += cost(e);
  while (held_ > budget_ && !uses_.empty()) {
    const auto victim = entries_.find(uses_.back());
    held_ -= cost(victim->second);
    entries_.erase(victim);
    uses_.pop_back();
  }
  return bytes;
}

void CachedStorage::forget(const std::string& key) const {
  const std::lock_guard lock(mutex_);
  const auto it = entries_.find(key);
  if (it == entries_.end()) return;
  held_ -= cost(it->second);
  uses_.erase(it->second.use);
  entries_.erase(it);
}

}  // namespace tessera
