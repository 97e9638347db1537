#pragma once
// Wall-clock timing shared by the CLI, the benchmarks, the viewer and the
// compositor, so that every command reports frame times the same way.
#include <chrono>
#include <vector>

namespace tessera {

// Milliseconds from `t0` to now on the steady clock.
inline double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The median: the middle value, or the mean of the two middle values for an
// even count; 0 for no values.
double median(std::vector<double> values);

}  // namespace tessera
