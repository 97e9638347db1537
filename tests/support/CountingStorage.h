#pragma once
// A folder store that counts the gets of each chunk key (metadata keys, whose
// last part starts with '.', are not counted): what tests of chunk reads
// assert exactly instead of timing.
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "tessera/io/ZarrStorage.h"

namespace tessera::test {

class CountingStorage final : public ZarrStorage {
 public:
  explicit CountingStorage(std::filesystem::path root) : inner_(std::move(root)) {}
  std::optional<std::vector<std::byte>> get(const std::string& key,
                                            std::uint64_t maxBytes) const override {
    {
      const std::lock_guard lock(mutex_);
      if (key.find("/.") == std::string::npos && key[0] != '.') ++gets_[key];
    }
    return inner_.get(key, maxBytes);
  }
  std::string locate(const std::string& key) const override { return inner_.locate(key); }
  std::string describe() const override { return inner_.describe(); }
  std::map<std::string, int> gets() const {
    const std::lock_guard lock(mutex_);
    return gets_;
  }
  void reset() {
    const std::lock_guard lock(mutex_);
    gets_.clear();
  }

 private:
  FolderStorage inner_;
  mutable std::mutex mutex_;
  mutable std::map<std::string, int> gets_;
};

}  // namespace tessera::test
