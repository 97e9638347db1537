#include "tessera/io/ZarrStorage.h"

#include <system_error>

#include "tessera/core/Error.h"
#include "tessera/io/ByteSource.h"

namespace tessera {

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
