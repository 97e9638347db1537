#pragma once
// Helpers every test suite may use: a temporary directory that removes
// itself, and a scoped override of the host-memory budget.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <random>
#include <string>

#include <unistd.h>

#include "tessera/core/HostBudget.h"

namespace tessera::test {

// A fresh directory under the system temp dir, removed with its contents.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            ("tessera-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + "-" +
             std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path file(const std::string& name) const { return path_ / name; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

// Sets the global host budget for one test and restores it afterwards, so
// that a failing assertion cannot leave other tests with a tiny budget.
class BudgetOverride {
 public:
  explicit BudgetOverride(std::uint64_t bytes) : saved_(HostBudget::global().limitBytes()) {
    HostBudget::global().setLimit(bytes);
  }
  ~BudgetOverride() { HostBudget::global().setLimit(saved_); }
  BudgetOverride(const BudgetOverride&) = delete;
  BudgetOverride& operator=(const BudgetOverride&) = delete;

 private:
  std::uint64_t saved_;
};

}  // namespace tessera::test
