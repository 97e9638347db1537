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

const FetchStorage::Entry* FetchStorage::arrived(const std::string& key) const {
  const auto it = entries_.find(key);
  if (it == entries_.end()) {
    want(key);
    throw KeyNotFetched(locate(key) + ": not fetched yet");
  }
  const Entry& e = it->second;
  uses_.splice(uses_.begin(), uses_, e.use);
  switch (e.state) {
    case State::Missing:
      return nullptr;
    case State::Failed:
      throw Error(e.error);
    case State::Bytes:
      break;
  }
  return &e;
}

std::optional<std::vector<std::byte>> FetchStorage::get(const std::string& key,
                                                        std::uint64_t maxBytes) const {
  const Entry* e = arrived(key);
  if (!e) return std::nullopt;
  if (e->bytes.size() > maxBytes) {
    throw InputError(locate(key) + ": " + std::to_string(e->bytes.size()) +
                     " bytes, more than the " + std::to_string(maxBytes) + " this key may hold");
  }
  return e->bytes;
}

std::string FetchStorage::rangeKey(const std::string& key, std::int64_t offset,
                                   std::uint64_t length) {
  std::string range = key;
  range.append("#bytes=");
  if (offset < 0) return range.append("-").append(std::to_string(length));
  return range.append(std::to_string(offset))
      .append("-")
      .append(std::to_string(std::uint64_t(offset) + length - 1));
}

std::string FetchStorage::keyOf(const ZarrStoredRead& read) {
  return read.whole ? read.key : rangeKey(read.key, read.offset, read.length);
}

std::optional<ZarrRange> FetchStorage::getRange(const std::string& key, std::int64_t offset,
                                                std::uint64_t length,
                                                std::uint64_t maxWhole) const {
  if (length == 0) throw InputError(locate(key) + ": an empty range asked");
  const std::string range = rangeKey(key, offset, length);
  const Entry* e = arrived(range);
  if (!e) return std::nullopt;
  const std::string where = url_ + "/" + range;
  if (e->total > maxWhole) {
    throw InputError(where + ": " + std::to_string(e->total) + " bytes, more than the " +
                     std::to_string(maxWhole) + " any valid content of this key can have");
  }
  // An inner chunk the page decoded is checked by the store's decoder.
  if (!e->decoded && e->bytes.size() != length) {
    throw InputError(where + ": answered with " + std::to_string(e->bytes.size()) +
                     " bytes, expected " + std::to_string(length));
  }
  return ZarrRange{e->bytes, e->total};
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

void FetchStorage::putRange(const std::string& rangeKey, std::vector<std::byte> bytes,
                            std::uint64_t total, bool decoded) {
  ++stats_.keys;
  ++stats_.ranges;
  stats_.bytes += bytes.size();
  Entry e;
  e.bytes = std::move(bytes);
  e.total = total;
  e.decoded = decoded;
  insert(rangeKey, std::move(e));
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
