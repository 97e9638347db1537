#pragma once
// The browser's OME-Zarr storage (io/ZarrStorage.h): keys are read with
// fetch() by the page (frontends/web/zarr-url.js), asynchronously, and handed over
// here; the single-threaded page never waits on the network. get() of a key
// that has not arrived records it as wanted and throws KeyNotFetched; the
// page fetches what is wanted (retries with back-off, errors naming the
// URL) and the caller asks again. A 404 is a missing key (a missing chunk
// reads as fill_value, as Zarr defines); a key whose fetch kept failing
// holds its error, which get() throws (the streamer keeps the coarser
// level on screen), until ready() asks for it again after retryMs.
// Arrived bytes are kept least recently used first out within a budget.
// Part of a key (a shard's index, one inner chunk: getRange) is a key of
// its own, "KEY#bytes=A-B" or "KEY#bytes=-N" (rangeKey), which the page
// fetches with a Range request and hands over with the value's whole size
// (putRange); a server that ignores Range is the page's to cope with
// (it cuts the range out of the whole body).
#include <cstdint>
#include <list>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "tessera/core/Error.h"
#include "tessera/io/ZarrStorage.h"

namespace tessera::web {

// get() of a key the page has not fetched yet.
class KeyNotFetched : public Error {
 public:
  using Error::Error;
};

struct FetchStats {
  std::uint64_t keys = 0;       // keys that arrived (bytes or 404)
  std::uint64_t bytes = 0;      // stored bytes that arrived
  std::uint64_t ranges = 0;     // of the keys, ranges of a value (putRange)
  std::uint64_t missing = 0;    // of them 404s
  std::uint64_t failed = 0;     // fetches that gave up
  std::uint64_t heldBytes = 0;  // bytes held now
};

class FetchStorage final : public ZarrStorage {
 public:
  // `url`: the store's root, without a trailing slash.
  FetchStorage(std::string url, std::uint64_t budgetBytes, double retryMs = 3000.0);

  std::optional<std::vector<std::byte>> get(const std::string& key,
                                            std::uint64_t maxBytes) const override;
  std::optional<ZarrRange> getRange(const std::string& key, std::int64_t offset,
                                    std::uint64_t length, std::uint64_t maxWhole) const override;
  // The key under which the range of `key` is fetched and held.
  static std::string rangeKey(const std::string& key, std::int64_t offset, std::uint64_t length);
  // The key a read is fetched under: its key, or its rangeKey.
  static std::string keyOf(const ZarrStoredRead& read);
  std::string locate(const std::string& key) const override { return url_ + "/" + key; }
  std::string describe() const override { return url_; }
  int parallelism() const override { return 1; }  // no threads; the page fetches in parallel
  // The page decodes chunks as they arrive, once each (frontends/web/zarr-url.js:
  // zlib and gzip with pako, blosc and zstd with numcodecs) when it has the
  // decoder (setPageDecodes); the io decoders (frontends/web/src/ZarrCodecsWeb.cpp)
  // are the fallback.
  bool decodesChunks(ZarrCompressor c) const override;
  void setPageDecodes(ZarrCompressor c) { pageDecodes_[static_cast<int>(c)] = true; }

  // True when `key` has arrived (bytes, a 404 or an error), and it becomes
  // the most recently used; otherwise records it as wanted.
  bool ready(const std::string& key) const;
  // Whether the key has arrived (or is known missing), without asking for it.
  bool holds(const std::string& key) const { return entries_.count(key) != 0; }
  // The keys wanted since the last call, in the order they were first
  // wanted (most urgent first), and forgets them.
  std::vector<std::string> takeWanted() const;
  bool hasWanted() const { return !wanted_.empty(); }

  void put(const std::string& key, std::vector<std::byte> bytes);
  // A range key's bytes, `total` the whole value's size (Content-Range);
  // `decoded`: an inner chunk the page decoded (decodesChunks), else the
  // range's bytes as stored.
  void putRange(const std::string& rangeKey, std::vector<std::byte> bytes, std::uint64_t total,
                bool decoded);
  void putMissing(const std::string& key);
  void putFailed(const std::string& key, const std::string& message);
  FetchStats stats() const { return stats_; }
  std::uint64_t budgetBytes() const { return budget_; }

 private:
  enum class State { Bytes, Missing, Failed };
  struct Entry {
    State state = State::Bytes;
    std::vector<std::byte> bytes;
    std::uint64_t total = 0;  // a range's: the whole value's size
    bool decoded = false;     // a range the page decoded
    std::string error;
    double failedAtMs = 0.0;
    std::list<std::string>::iterator use;
  };
  void insert(const std::string& key, Entry entry);
  // The entry of `key`, the most recently used now; KeyNotFetched (and
  // wanted) when it has not arrived; its error when it failed.
  const Entry* arrived(const std::string& key) const;
  void want(const std::string& key) const;
  void erase(const std::string& key) const;

  std::string url_;
  bool pageDecodes_[8] = {};
  std::uint64_t budget_;
  double retryMs_;
  mutable FetchStats stats_;
  mutable std::list<std::string> uses_;  // most recent first
  mutable std::unordered_map<std::string, Entry> entries_;
  mutable std::vector<std::string> wanted_;
  mutable std::unordered_map<std::string, bool> wantedSet_;
};

}  // namespace tessera::web
