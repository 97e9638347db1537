#include "tessera/core/Histogram.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "tessera/core/Error.h"

namespace tessera {
namespace {

// A 1-row volume holding `values` in order.
Volume lineVolume(ScalarType type, const std::vector<double>& values) {
  Volume v = Volume::allocate({static_cast<int>(values.size()), 1, 1}, type, "test");
  for (std::size_t i = 0; i < values.size(); ++i) v.setValueAtIndex(i, values[i]);
  return v;
}

TEST(Histogram, CountsEachValueOfASmallU8Volume) {
  Volume v = Volume::allocate({4, 2, 1}, ScalarType::U8, "test");
  const std::vector<double> values = {0, 0, 1, 2, 3, 3, 3, 255};
  for (std::size_t i = 0; i < values.size(); ++i) v.setValueAtIndex(i, values[i]);

  const Histogram h = Histogram::compute(v, 256, {0.0, 255.0});
  ASSERT_EQ(h.bins(), 256);
  EXPECT_EQ(h.total(), 8u);
  EXPECT_EQ(h.counts()[0], 2u);
  EXPECT_EQ(h.counts()[1], 1u);
  EXPECT_EQ(h.counts()[2], 1u);
  EXPECT_EQ(h.counts()[3], 3u);
  EXPECT_EQ(h.counts()[255], 1u);
  std::uint64_t sum = 0;
  for (std::uint64_t c : h.counts()) sum += c;
  EXPECT_EQ(sum, 8u);
  EXPECT_DOUBLE_EQ(h.mean(), (0 + 0 + 1 + 2 + 3 + 3 + 3 + 255) / 8.0);
}

TEST(Histogram, EveryU8ValueGetsItsOwnBinOverTheFullRange) {
  std::vector<double> values(256);
  for (int i = 0; i < 256; ++i) values[static_cast<std::size_t>(i)] = i;
  const Histogram h = Histogram::compute(lineVolume(ScalarType::U8, values), 256);
  EXPECT_EQ(h.range().min, 0.0);
  EXPECT_EQ(h.range().max, 255.0);
  for (int i = 0; i < 256; ++i) EXPECT_EQ(h.counts()[static_cast<std::size_t>(i)], 1u) << i;
  EXPECT_DOUBLE_EQ(h.mean(), 127.5);
}

TEST(Histogram, ValuesOutsideTheRangeGoToTheEndBins) {
  const Volume v = lineVolume(ScalarType::U16, {0, 5, 10, 15, 20, 25, 1000});
  const Histogram h = Histogram::compute(v, 10, {10.0, 20.0});
  EXPECT_EQ(h.total(), 7u);
  EXPECT_EQ(h.counts()[0], 3u);              // 0, 5 below; 10 at the lower edge
  EXPECT_EQ(h.counts()[5], 1u);              // 15
  EXPECT_EQ(h.counts()[9], 3u);              // 20 at the upper edge; 25, 1000 above
  EXPECT_DOUBLE_EQ(h.mean(), 1075.0 / 7.0);  // the mean is of the raw values
}

TEST(Histogram, SignedValuesAndBinCentres) {
  std::vector<double> values;
  for (int i = -100; i < 0; ++i) values.push_back(i);
  const Histogram h = Histogram::compute(lineVolume(ScalarType::I16, values), 10, {-100.0, 0.0});
  for (int b = 0; b < 10; ++b) EXPECT_EQ(h.counts()[static_cast<std::size_t>(b)], 10u) << b;
  EXPECT_DOUBLE_EQ(h.mean(), -50.5);
  EXPECT_DOUBLE_EQ(h.binCenter(0), -95.0);
  EXPECT_DOUBLE_EQ(h.binCenter(9), -5.0);
}

TEST(Histogram, PercentileInterpolatesWithinBins) {
  std::vector<double> values;
  for (int i = 0; i < 100; ++i) values.push_back(i);
  const Volume v = lineVolume(ScalarType::U8, values);

  // One voxel per unit-wide bin [k, k+1): the p-th fraction lies at 100 p.
  const Histogram fine = Histogram::compute(v, 100, {0.0, 100.0});
  EXPECT_DOUBLE_EQ(fine.percentile(0.0), 0.0);
  EXPECT_DOUBLE_EQ(fine.percentile(0.25), 25.0);
  EXPECT_DOUBLE_EQ(fine.percentile(0.5), 50.0);
  EXPECT_DOUBLE_EQ(fine.percentile(1.0), 100.0);

  // Ten voxels per bin of width 10: linear within the bin.
  const Histogram coarse = Histogram::compute(v, 10, {0.0, 100.0});
  EXPECT_DOUBLE_EQ(coarse.percentile(0.55), 55.0);
  EXPECT_DOUBLE_EQ(coarse.percentile(0.05), 5.0);
  EXPECT_DOUBLE_EQ(coarse.percentile(0.99), 99.0);
}

TEST(Histogram, PercentileSkipsEmptyBins) {
  // Two clusters: 0 and 200; nothing between.
  const Volume v = lineVolume(ScalarType::U8, {0, 0, 200, 200});
  const Histogram h = Histogram::compute(v, 256, {0.0, 256.0});
  EXPECT_DOUBLE_EQ(h.percentile(0.5), 1.0);                  // upper edge of bin 0
  EXPECT_DOUBLE_EQ(h.percentile(0.5 + 1e-9), 200.0 + 2e-9);  // just into bin 200
  EXPECT_DOUBLE_EQ(h.percentile(1.0), 201.0);
}

TEST(Histogram, F32SkipsNaNAndKeepsInfOutOfTheMean) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const Volume v = lineVolume(ScalarType::F32, {0.5, nan, 1.5, nan, 2.5, 3.5, inf, -inf});
  const Histogram h = Histogram::compute(v, 4, {0.0, 4.0});
  EXPECT_EQ(h.total(), 6u);      // two NaN skipped
  EXPECT_EQ(h.counts()[0], 2u);  // 0.5 and -inf
  EXPECT_EQ(h.counts()[1], 1u);
  EXPECT_EQ(h.counts()[2], 1u);
  EXPECT_EQ(h.counts()[3], 2u);     // 3.5 and +inf
  EXPECT_DOUBLE_EQ(h.mean(), 2.0);  // of the four finite values

  // Default range: the volume's value range, which ignores NaN/Inf too.
  const Histogram d = Histogram::compute(v, 3);
  EXPECT_DOUBLE_EQ(d.range().min, 0.5);
  EXPECT_DOUBLE_EQ(d.range().max, 3.5);
  EXPECT_EQ(d.counts()[0], 2u);  // 0.5, -inf
  EXPECT_EQ(d.counts()[1], 1u);  // 1.5
  EXPECT_EQ(d.counts()[2], 3u);  // 2.5 (= edge 2.5), 3.5, +inf
}

TEST(Histogram, ConstantVolumeCountsEverythingInTheFirstBin) {
  const Volume v = Volume::allocate({3, 3, 3}, ScalarType::U16, "test");  // all zero
  const Histogram h = Histogram::compute(v, 16);
  EXPECT_EQ(h.total(), 27u);
  EXPECT_EQ(h.counts()[0], 27u);
  EXPECT_EQ(h.mean(), 0.0);
  EXPECT_EQ(h.percentile(0.5), 0.0);
}

TEST(Histogram, RejectsBadArguments) {
  const Volume v = lineVolume(ScalarType::U8, {1, 2, 3});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(Histogram::compute(v, 0), InputError);
  EXPECT_THROW(Histogram::compute(v, -4), InputError);
  EXPECT_THROW(Histogram::compute(v, 8, {nan, 1.0}), InputError);
  EXPECT_THROW(Histogram::compute(v, 8, {5.0, 1.0}), InputError);
  EXPECT_THROW(Histogram::compute(v, 8, {0.0, std::numeric_limits<double>::infinity()}),
               InputError);
  const Histogram h = Histogram::compute(v, 8);
  EXPECT_THROW(h.percentile(-0.1), InputError);
  EXPECT_THROW(h.percentile(1.5), InputError);
  EXPECT_THROW(h.percentile(nan), InputError);

  const Volume allNan = lineVolume(ScalarType::F32, {nan, nan});
  const Histogram empty = Histogram::compute(allNan, 8);
  EXPECT_EQ(empty.total(), 0u);
  EXPECT_THROW(empty.percentile(0.5), InputError);
}

}  // namespace
}  // namespace tessera
