#include "ZarrFetchStorage.h"

#include <chrono>

namespace tessera::web {

namespace {

double nowMs() {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

FetchStorage::FetchStorage(std::string url, std::uint64_t budgetBytes, double retryMs)
    : url_(std::move(url)), budget_(budgetBytes), retryMs_(retryMs) {
  while (!url_.empty() && url_.back() == '/') url_.pop_back();
}

void FetchStorage::want(const std::string& key) const {
  if (wantedSet_.emplace(key, true).second) wanted_.push_back(key);
}

bool FetchStorage::decodesChunks(ZarrCompressor c) const {
  return c != ZarrCompressor::None && pageDecodes_[static_cast<int>(c)];
}

bool FetchStorage::ready(const std::string& key) const {
  const auto it = entries_.find(key);
  if (it != entries_.end()) {
    const Entry& e = it->second;
    if (e.state != State::Failed || nowMs() - e.failedAtMs < retryMs_) {
      // Asked for now: the most recently used, so that the keys fetched for
      // the same read (those it lacks) push others out first, not it.
      uses_.splice(uses_.begin(), uses_, e.use);
      return true;
    }
    erase(key);  // failed a while ago: fetched again
  }
  want(key);
  return false;
}

void FetchStorage::erase(const std::string& key) const {
  const auto it = entries_.find(key);
  if (it == entries_.end()) return;
  stats_.heldBytes -= it->second.bytes.size();
  uses_.erase(it->second.use);
  entries_.erase(it);
}

std::vector<std::string> FetchStorage::takeWanted() const {
  std::vector<std::string> keys;
  keys.swap(wanted_);
  wantedSet_.clear();
  return keys;
}

std::optional<std::vector<std::byte>> FetchStorage::get(const std::string& key,
                                                        std::uint64_t maxBytes) const {
  const auto it = entries_.find(key);
  if (it == entries_.end()) {
    want(key);
    throw KeyNotFetched(locate(key) + ": not fetched yet");
  }
  Entry& e = it->second;
  uses_.splice(uses_.begin(), uses_, e.use);
  switch (e.state) {
    case State::Missing:
      return std::nullopt;
    case State::Failed:
      throw Error(e.error);
    case State::Bytes:
      break;
  }
  if (e.bytes.size() > maxBytes) {
    throw InputError(locate(key) + ": " + std::to_string(e.bytes.size()) +
                     " bytes, more than the " + std::to_string(maxBytes) + " this key may hold");
  }
  return e.bytes;
}

void FetchStorage::insert(const std::string& key, Entry entry) {
  erase(key);
  uses_.push_front(key);
  entry.use = uses_.begin();
  stats_.heldBytes += entry.bytes.size();
  entries_.emplace(key, std::move(entry));
  // Least recently used out while over the budget; the newest stays.
  while (stats_.heldBytes > budget_ && uses_.size() > 1) {
    const auto victim = entries_.find(uses_.back());
    stats_.heldBytes -= victim->second.bytes.size();
    entries_.erase(victim);
    uses_.pop_back();
  }
}

void FetchStorage::put(const std::string& key, std::vector<std::byte> bytes) {
  ++stats_.keys;
  stats_.bytes += bytes.size();
  Entry e;
  e.bytes = std::move(bytes);
  insert(key, std::move(e));
}

void FetchStorage::putMissing(const std::string& key) {
  ++stats_.keys;
  ++stats_.missing;
  Entry e;
  e.state = State::Missing;
  insert(key, std::move(e));
}

void FetchStorage::putFailed(const std::string& key, const std::string& message) {
  ++stats_.failed;
  Entry e;
  e.state = State::Failed;
  e.error = message;
  e.failedAtMs = nowMs();
  insert(key, std::move(e));
}

}  // namespace tessera::web
