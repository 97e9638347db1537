#include "tessera/core/HostBudget.h"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "tessera/core/Error.h"

namespace tessera {

namespace {
std::uint64_t defaultLimit() {
  if (const char* env = std::getenv("TESSERA_HOST_BUDGET_MB")) {
    char* end = nullptr;
    const unsigned long long mb = std::strtoull(env, &end, 10);
    if (end != env && *end == '\0' && mb > 0) {
      // Saturate: a huge value means "no practical limit", not a wrapped-around small one.
      constexpr unsigned long long kMaxMb = UINT64_MAX >> 20;
      return mb > kMaxMb ? UINT64_MAX : static_cast<std::uint64_t>(mb) << 20;
    }
  }
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long pageSize = sysconf(_SC_PAGE_SIZE);
  if (pages > 0 && pageSize > 0) {
    return static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(pageSize) / 2;
  }
  return 4ull << 30;
}
}  // namespace

HostBudget& HostBudget::global() {
  static HostBudget budget(defaultLimit());
  return budget;
}

void HostBudget::check(std::uint64_t bytes, const std::string& what) const {
  if (bytes > limit_) {
    throw BudgetError(what + ": needs " + formatBytes(bytes) + " of host memory, budget is " +
                      formatBytes(limit_) + " (set TESSERA_HOST_BUDGET_MB to change it)");
  }
}

std::string formatBytes(std::uint64_t bytes) {
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB"};
  double v = static_cast<double>(bytes);
  int u = 0;
  while (v >= 1024.0 && u < 5) {
    v /= 1024.0;
    ++u;
  }
  char buf[64];
  if (u == 0) {
    std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(bytes));
  } else {
    std::snprintf(buf, sizeof buf, "%.1f", v);
  }
  std::string text = buf;
  // The header's format: "200 MiB", not "200.0 MiB"; "1.5 GiB" keeps its decimal.
  if (u > 0) {
    if (text.size() > 2 && text.compare(text.size() - 2, 2, ".0") == 0)
      text.resize(text.size() - 2);
    text += std::string(" ") + units[u];
  }
  return text;
}

}  // namespace tessera
