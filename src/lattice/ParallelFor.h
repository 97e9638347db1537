#pragma once
// Work split over threads for the lattice's per-point loops.
#include <cstdint>
#include <functional>

namespace tessera::lattice::detail {

// Calls body(begin, end) on disjoint, contiguous chunks covering [0, n), on
// up to `threads` threads (0: every hardware thread; small n stays on the
// calling thread), and rethrows the first exception a chunk threw.
void parallelFor(std::int64_t n, int threads,
                 const std::function<void(std::int64_t, std::int64_t)>& body);

}  // namespace tessera::lattice::detail
