#pragma once
// The host-memory budget every large allocation is checked against, so that a
// header claiming 2^31 voxels is refused with numbers instead of exhausting RAM.
#include <cstdint>
#include <string>

namespace tessera {

class HostBudget {
 public:
  // Process-wide budget. Default: half of physical memory, overridable with
  // the TESSERA_HOST_BUDGET_MB environment variable or setLimit().
  static HostBudget& global();

  std::uint64_t limitBytes() const { return limit_; }
  void setLimit(std::uint64_t bytes) { limit_ = bytes; }

  // Throws BudgetError naming `what` if `bytes` exceeds the budget.
  void check(std::uint64_t bytes, const std::string& what) const;

 private:
  explicit HostBudget(std::uint64_t limit) : limit_(limit) {}
  std::uint64_t limit_;
};

// "1.5 GiB", "200 MiB", "12 KiB", "17 B".
std::string formatBytes(std::uint64_t bytes);

}  // namespace tessera
