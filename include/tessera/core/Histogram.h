#pragma once
#include <cstdint>
#include <vector>

#include "tessera/core/Volume.h"

namespace tessera {

// Histogram of a volume's raw values over `range`, `bins` equal-width bins
// (values outside the range are counted in the end bins; NaN is skipped).
// InputError if bins < 1 or the range is not finite with min <= max.
class Histogram {
 public:
  static Histogram compute(const Volume& volume, int bins, ValueRange range);
  static Histogram compute(const Volume& volume, int bins = 256) {
    return compute(volume, bins, volume.valueRange());
  }

  const std::vector<std::uint64_t>& counts() const { return counts_; }
  ValueRange range() const { return range_; }
  std::uint64_t total() const { return total_; }
  int bins() const { return static_cast<int>(counts_.size()); }
  // Raw value below which `fraction` (0..1) of the counted voxels lie
  // (bin-resolution, linear within the bin).
  // InputError if fraction is outside [0,1] or nothing was counted.
  double percentile(double fraction) const;
  // Mean of the counted finite values (f32 +-Inf lands in an end bin but not
  // in the mean); 0 if there are none.
  double mean() const { return mean_; }
  // Centre value of bin i.
  double binCenter(int i) const;

 private:
  std::vector<std::uint64_t> counts_;
  ValueRange range_;
  std::uint64_t total_ = 0;
  double mean_ = 0.0;
};

}  // namespace tessera
