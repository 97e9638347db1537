#pragma once
// Where a Zarr store's keys live ("0/.zarray", "0/1/2/3", "0/c/1/2/3"): a folder on
// disk, bytes in memory (tests, fuzzers, and the browser, where a JS
// fetch() source fills it), or an HTTP(S) server (io/HttpStorage.h). The
// store reader (io/ZarrStore.h) sees only this interface.
#include <cstdint>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "tessera/io/ZarrArray.h"

namespace tessera {

// Part of a key's bytes (a shard's index, one inner chunk) and the size
// of the whole value.
struct ZarrRange {
  std::vector<std::byte> bytes;
  std::uint64_t total = 0;
};

// One read a store makes of its storage: a whole key's value, or bytes
// [offset, offset + length) of it (offset < 0: its last `length` bytes),
// as getRange reads them.
struct ZarrStoredRead {
  std::string key;
  bool whole = true;
  std::int64_t offset = 0;
  std::uint64_t length = 0;
};

class ZarrStorage {
 public:
  virtual ~ZarrStorage() = default;

  // Bytes [offset, offset + length) of `key`, or with offset < 0 its last
  // `length` bytes (a shard's index at its end); nullopt when there is no
  // such key. A range outside the value: InputError naming the key. A
  // value larger than `maxWhole` is an InputError too. The default reads
  // the whole value (get) and cuts the range out; folders and HTTP read
  // only the range.
  virtual std::optional<ZarrRange> getRange(const std::string& key, std::int64_t offset,
                                            std::uint64_t length, std::uint64_t maxWhole) const;

  // The bytes stored under `key`, or nullopt when there are none (a
  // missing chunk is fill_value in Zarr). More than `maxBytes` is an
  // InputError naming the key's location, before it is all held.
  // Unreachable or failing storage: Error naming the location.
  // Thread-safe.
  virtual std::optional<std::vector<std::byte>> get(const std::string& key,
                                                    std::uint64_t maxBytes) const = 0;
  // Where `key` lives, for messages: a path or a URL.
  virtual std::string locate(const std::string& key) const = 0;
  // Drops what a cache holds for `key` (its bytes failed to decode and are
  // fetched again); storage without a cache has nothing to drop.
  virtual void forget(const std::string& key) const { (void)key; }
  // How often a chunk that fails to decode is fetched again: 0 where the
  // same bytes would come back (disk, memory); a network may have
  // delivered a damaged body.
  virtual int refetches() const { return 0; }
  // True when get() hands over the chunks of arrays with this compressor
  // decoded already: the browser's storage, whose page decodes each chunk
  // once as it arrives (pako; numcodecs' WebAssembly blosc and zstd, as
  // Debian's libblosc and libzstd are native only). ZarrStore then checks
  // their size instead of decoding them. For Zarr v3 that is the chunk's
  // compressor undone and its crc32c checked (the bytes and transpose
  // codecs are ZarrStore's); a shard's inner chunk read as a range too.
  virtual bool decodesChunks(ZarrCompressor compressor) const {
    (void)compressor;
    return false;
  }
  // How many chunk reads are worth having in flight at once.
  virtual int parallelism() const { return 2; }
  // The store's root for `info`: a folder or a URL.
  virtual std::string describe() const = 0;
};

// A store on disk: keys are relative paths under `root`, read through
// io's FileSource.
class FolderStorage final : public ZarrStorage {
 public:
  explicit FolderStorage(std::filesystem::path root);
  std::optional<std::vector<std::byte>> get(const std::string& key,
                                            std::uint64_t maxBytes) const override;
  std::optional<ZarrRange> getRange(const std::string& key, std::int64_t offset,
                                    std::uint64_t length, std::uint64_t maxWhole) const override;
  std::string locate(const std::string& key) const override;
  std::string describe() const override { return root_.string(); }

 private:
  std::filesystem::path root_;
};

// A store in memory, keyed by the same relative names.
class MemoryStorage final : public ZarrStorage {
 public:
  explicit MemoryStorage(std::string name) : name_(std::move(name)) {}
  void put(const std::string& key, std::vector<std::byte> bytes);
  std::optional<std::vector<std::byte>> get(const std::string& key,
                                            std::uint64_t maxBytes) const override;
  std::string locate(const std::string& key) const override { return name_ + "/" + key; }
  std::string describe() const override { return name_; }

 private:
  std::string name_;
  mutable std::mutex mutex_;
  std::map<std::string, std::vector<std::byte>> entries_;
};

}  // namespace tessera
