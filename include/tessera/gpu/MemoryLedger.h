#pragma once
// Counts the bytes of every GPU texture and buffer Tessera allocates, so that
// memory figures are measured rather than estimated, and so a device budget
// can be enforced (exceeding it is a planner bug: BudgetError).
#include <cstdint>
#include <map>
#include <string>

namespace tessera::gpu {

enum class GpuResource { Texture, Buffer, Renderbuffer };

class MemoryLedger {
 public:
  using Id = std::uint64_t;

  // 0 = unlimited.
  void setBudget(std::uint64_t bytes) { budget_ = bytes; }
  std::uint64_t budget() const { return budget_; }

  // Records an allocation; throws BudgetError (naming `label`) if it would
  // exceed the budget.
  Id add(GpuResource kind, std::uint64_t bytes, const std::string& label);
  void remove(Id id);

  std::uint64_t totalBytes() const { return total_; }
  std::uint64_t bytes(GpuResource kind) const;
  std::uint64_t peakBytes() const { return peak_; }
  std::size_t count() const { return entries_.size(); }

 private:
  struct Entry {
    GpuResource kind;
    std::uint64_t bytes;
    std::string label;
  };
  std::map<Id, Entry> entries_;
  Id next_ = 1;
  std::uint64_t total_ = 0;
  std::uint64_t peak_ = 0;
  std::uint64_t budget_ = 0;
};

}  // namespace tessera::gpu
