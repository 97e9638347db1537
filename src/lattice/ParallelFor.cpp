#include "lattice/ParallelFor.h"

#include <algorithm>
#include <exception>
#include <thread>
#include <vector>

namespace tessera::lattice::detail {

void parallelFor(std::int64_t n, int threads,
                 const std::function<void(std::int64_t, std::int64_t)>& body) {
  constexpr std::int64_t kMinPerThread = 4096;  // below this, start-up costs more than it saves
  const int hw = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const std::int64_t wanted = threads > 0 ? threads : hw;
  const std::int64_t count = std::clamp<std::int64_t>(n / kMinPerThread, 1, wanted);
  if (count <= 1) {
    if (n > 0) body(0, n);
    return;
  }
  std::vector<std::thread> pool;
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(count));
  for (std::int64_t t = 0; t < count; ++t) {
    pool.emplace_back([&, t] {
      try {
        body(n * t / count, n * (t + 1) / count);
      } catch (...) {
        errors[static_cast<std::size_t>(t)] = std::current_exception();
      }
    });
  }
  for (auto& th : pool) th.join();
  for (const auto& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

}  // namespace tessera::lattice::detail
