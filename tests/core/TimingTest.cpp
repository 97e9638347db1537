// One median for every command: two reports of the same frames agree.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "tessera/core/Timing.h"

using namespace tessera;

TEST(Timing, MedianOfAnEvenCountIsTheMeanOfTheTwoMiddleValues) {
  EXPECT_DOUBLE_EQ(median({4.0, 1.0, 3.0, 2.0}), 2.5);
  EXPECT_DOUBLE_EQ(median({10.0, 30.0}), 20.0);
}

TEST(Timing, MedianOfAnOddCountIsTheMiddleValue) {
  EXPECT_DOUBLE_EQ(median({5.0, 1.0, 3.0}), 3.0);
  EXPECT_DOUBLE_EQ(median({7.0}), 7.0);
  EXPECT_DOUBLE_EQ(median({}), 0.0);
}

TEST(Timing, MsSinceMeasuresTheSteadyClock) {
  const auto t0 = std::chrono::steady_clock::now();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const double ms = msSince(t0);
  EXPECT_GE(ms, 20.0);
  EXPECT_LT(ms, 2000.0);
}
