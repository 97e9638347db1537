#include "tessera/io/ZarrStorage.h"

#include <algorithm>
#include <system_error>

#include "tessera/core/Error.h"
#include "tessera/io/ByteSource.h"

namespace tessera {

namespace {

// The range [begin, end) that (offset, length) asks of a value of `total`
// bytes; InputError naming `where` when it lies outside.
std::pair<std::uint64_t, std::uint64_t> rangeWithin(std::int64_t offset, std::uint64_t length,
                                                    std::uint64_t total, const std::string& where) {
  const std::uint64_t begin = offset < 0 ? total - std::min(total, length) : std::uint64_t(offset);
  if ((offset < 0 && length > total) || begin > total || length > total - begin) {
    throw InputError(where + ": bytes " +
                     (offset < 0 ? "-" + std::to_string(length)
                                 : std::to_string(begin) + ".." + std::to_string(begin + length)) +
                     " asked of a value of " + std::to_string(total) + " bytes");
  }
  return {begin, begin + length};
}

}  // namespace

std::optional<ZarrRange> ZarrStorage::getRange(const std::string& key, std::int64_t offset,
                                               std::uint64_t length, std::uint64_t maxWhole) const {
  auto whole = get(key, maxWhole);
  if (!whole) return std::nullopt;
  const auto [b, e] = rangeWithin(offset, length, whole->size(), locate(key));
  ZarrRange r;
  r.total = whole->size();
  r.bytes.assign(whole->begin() + std::ptrdiff_t(b), whole->begin() + std::ptrdiff_t(e));
  return r;
}

std::optional<ZarrRange> FolderStorage::getRange(const std::string& key, std::int64_t offset,
                                                 std::uint64_t length,
                                                 std::uint64_t maxWhole) const {
  const std::filesystem::path path = root_ / key;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    if (std::filesystem::exists(path, ec)) throw InputError(path.string() + ": not a regular file");
    return std::nullopt;
  }
  const FileSource file(path);
  if (file.size() > maxWhole) {
    throw InputError(path.string() + ": " + std::to_string(file.size()) + " bytes, more than the " +
                     std::to_string(maxWhole) + " any valid content of this key can have");
  }
  const auto [b, e] = rangeWithin(offset, length, file.size(), path.string());
  ZarrRange r;
  r.total = file.size();
  r.bytes.resize(std::size_t(e - b));
  const std::size_t n = file.read(b, r.bytes.data(), r.bytes.size());
  if (n != r.bytes.size()) {
    throw InputError(path.string() + ": read " + std::to_string(n) + " of " +
                     std::to_string(r.bytes.size()) + " bytes at " + std::to_string(b));
  }
  return r;
}

FolderStorage::FolderStorage(std::filesystem::path root) : root_(std::move(root)) {}

std::string FolderStorage::locate(const std::string& key) const {
  return (root_ / key).string();
}

std::optional<std::vector<std::byte>> FolderStorage::get(const std::string& key,
                                                         std::uint64_t maxBytes) const {
  const std::filesystem::path path = root_ / key;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    if (std::filesystem::exists(path, ec)) {
      throw InputError(path.string() + ": not a regular file");
    }
    return std::nullopt;
  }
  const FileSource file(path);
  if (file.size() > maxBytes) {
    throw InputError(path.string() + ": " + std::to_string(file.size()) + " bytes, more than the " +
                     std::to_string(maxBytes) + " any valid content of this key can have");
  }
  std::vector<std::byte> bytes(static_cast<std::size_t>(file.size()));
  const std::size_t n = file.read(0, bytes.data(), bytes.size());
  if (n != bytes.size()) {
    throw InputError(path.string() + ": read " + std::to_string(n) + " of " +
                     std::to_string(bytes.size()) + " bytes");
  }
  return bytes;
}

void MemoryStorage::put(const std::string& key, std::vector<std::byte> bytes) {
  const std::lock_guard lock(mutex_);
  entries_[key] = std::move(bytes);
}

std::optional<std::vector<std::byte>> MemoryStorage::get(const std::string& key,
                                                         std::uint64_t maxBytes) const {
  const std::lock_guard lock(mutex_);
  const auto it = entries_.find(key);
  if (it == entries_.end()) return std::nullopt;
  if (it->second.size() > maxBytes) {
    throw InputError(locate(key) + ": " + std::to_string(it->second.size()) +
                     " bytes, more than the " + std::to_string(maxBytes) +
                     " any valid content of this key can have");
  }
  return it->second;
}

}  // namespace tessera
