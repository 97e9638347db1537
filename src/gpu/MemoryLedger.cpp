#include "tessera/gpu/MemoryLedger.h"

#include <algorithm>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"

namespace tessera::gpu {

MemoryLedger::Id MemoryLedger::add(GpuResource kind, std::uint64_t bytes,
                                   const std::string& label) {
  if (budget_ != 0 && total_ + bytes > budget_) {
    throw BudgetError(label + ": GPU allocation of " + formatBytes(bytes) +
                      " would bring the total to " + formatBytes(total_ + bytes) +
                      ", over the texture budget of " + formatBytes(budget_));
  }
  const Id id = next_++;
  entries_.emplace(id, Entry{kind, bytes, label});
  total_ += bytes;
  peak_ = std::max(peak_, total_);
  return id;
}

void MemoryLedger::remove(Id id) {
  auto it = entries_.find(id);
  if (it == entries_.end()) return;
  total_ -= it->second.bytes;
  entries_.erase(it);
}

std::uint64_t MemoryLedger::bytes(GpuResource kind) const {
  std::uint64_t sum = 0;
  for (const auto& [id, e] : entries_) {
    if (e.kind == kind) sum += e.bytes;
  }
  return sum;
}

}  // namespace tessera::gpu
