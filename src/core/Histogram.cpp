#include "tessera/core/Histogram.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>

#include "tessera/core/Error.h"

namespace tessera {

namespace {

// Bin of a raw value; below/above the range goes to the end bins. A zero-width
// range (a constant volume) puts everything at or below it into bin 0.
class Binner {
 public:
  Binner(ValueRange range, int bins) : range_(range), bins_(bins) {}

  std::size_t operator()(double v) const {
    if (v <= range_.min) return 0;
    if (v >= range_.max) return static_cast<std::size_t>(bins_ - 1);
    // Multiply before dividing: for integer values and widths the product is
    // exact, so a value on a bin edge is not rounded into the bin below.
    const double b = std::floor((v - range_.min) * bins_ / range_.width());
    // Rounding can push a value just below max onto `bins`.
    return static_cast<std::size_t>(std::min(b, static_cast<double>(bins_ - 1)));
  }

 private:
  ValueRange range_;
  int bins_;
};

// Integer voxels: count each distinct value once, then bin the (at most
// 65536) distinct values, instead of binning every voxel in floating point.
template <class T>
void countIntegers(const T* p, std::size_t n, const Binner& bin, std::vector<std::uint64_t>& counts,
                   std::uint64_t& total, double& sum) {
  constexpr std::int64_t lo = std::numeric_limits<T>::min();
  constexpr std::int64_t hi = std::numeric_limits<T>::max();
  std::vector<std::uint64_t> perValue(static_cast<std::size_t>(hi - lo + 1), 0);
  for (std::size_t i = 0; i < n; ++i) ++perValue[static_cast<std::size_t>(p[i] - lo)];
  for (std::int64_t v = lo; v <= hi; ++v) {
    const std::uint64_t c = perValue[static_cast<std::size_t>(v - lo)];
    if (c == 0) continue;
    counts[bin(static_cast<double>(v))] += c;
    total += c;
    sum += static_cast<double>(c) * static_cast<double>(v);
  }
}

void countFloats(const float* p, std::size_t n, const Binner& bin,
                 std::vector<std::uint64_t>& counts, std::uint64_t& total, double& sum,
                 std::uint64_t& finite) {
  for (std::size_t i = 0; i < n; ++i) {
    const double v = p[i];
    if (std::isnan(v)) continue;
    ++counts[bin(v)];
    ++total;
    // ±Inf is counted (in an end bin) but would make the mean meaningless.
    if (std::isfinite(v)) {
      sum += v;
      ++finite;
    }
  }
}

}  // namespace

Histogram Histogram::compute(const Volume& volume, int bins, ValueRange range) {
  if (bins < 1) {
    throw InputError("histogram: " + std::to_string(bins) + " bins requested, expected >= 1");
  }
  if (!std::isfinite(range.min) || !std::isfinite(range.max) || !std::isfinite(range.width()) ||
      range.max < range.min) {
    throw InputError("histogram: range [" + std::to_string(range.min) + ", " +
                     std::to_string(range.max) + "] is not a finite interval with min <= max");
  }
  Histogram h;
  h.range_ = range;
  h.counts_.assign(static_cast<std::size_t>(bins), 0);
  const Binner bin(range, bins);
  const std::size_t n = static_cast<std::size_t>(volume.voxelCount());
  double sum = 0.0;
  std::uint64_t meanCount = 0;
  switch (volume.type()) {
    case ScalarType::U8:
      countIntegers(volume.dataAs<std::uint8_t>(), n, bin, h.counts_, h.total_, sum);
      meanCount = h.total_;
      break;
    case ScalarType::U16:
      countIntegers(volume.dataAs<std::uint16_t>(), n, bin, h.counts_, h.total_, sum);
      meanCount = h.total_;
      break;
    case ScalarType::I16:
      countIntegers(volume.dataAs<std::int16_t>(), n, bin, h.counts_, h.total_, sum);
      meanCount = h.total_;
      break;
    case ScalarType::F32:
      countFloats(volume.dataAs<float>(), n, bin, h.counts_, h.total_, sum, meanCount);
      break;
  }
  h.mean_ = meanCount > 0 ? sum / static_cast<double>(meanCount) : 0.0;
  return h;
}

double Histogram::percentile(double fraction) const {
  if (!(fraction >= 0.0 && fraction <= 1.0)) {
    throw InputError("histogram percentile: fraction " + std::to_string(fraction) +
                     " is outside [0, 1]");
  }
  if (total_ == 0) {
    throw InputError("histogram percentile: the histogram is empty (no non-NaN voxels)");
  }
  const double binWidth = range_.width() / static_cast<double>(counts_.size());
  const double target = fraction * static_cast<double>(total_);
  double below = 0.0;  // voxels in the bins before i
  for (std::size_t i = 0; i < counts_.size(); ++i) {
    if (counts_[i] == 0) continue;
    const double c = static_cast<double>(counts_[i]);
    if (below + c >= target) {
      // The bin's voxels are taken as spread evenly across it.
      const double lower = range_.min + static_cast<double>(i) * binWidth;
      return lower + (target - below) / c * binWidth;
    }
    below += c;
  }
  return range_.max;  // only reached through rounding of `target` at fraction 1
}

double Histogram::binCenter(int i) const {
  return range_.min + (static_cast<double>(i) + 0.5) * range_.width() / bins();
}

}  // namespace tessera
