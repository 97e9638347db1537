// The platform roofline: every kernel compiles, runs and
// is timed, and bad options are refused. The rates themselves are
// benchmarks (`tessera bench --roofline`), never asserted.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "support/GpuTestContext.h"
#include "tessera/core/Error.h"
#include "tessera/render/Roofline.h"

using namespace tessera;

TEST(Roofline, CompilesRunsAndTimesEveryKernel) {
  const render::RooflineOptions options{.volumeDims = {24, 20, 16},
                                        .width = 128,
                                        .height = 96,
                                        .fetchesPerFragment = 32,
                                        .repeats = 2};
  const std::vector<render::RooflineRate> rates =
      render::measureRoofline(test::gpuContext(), options);
  ASSERT_EQ(rates.size(), 6u);
  std::set<int> kernels;
  for (const render::RooflineRate& r : rates) {
    kernels.insert(static_cast<int>(r.kernel));
    // Times only: a loaded machine may stall any pass, so no comparison of them.
    EXPECT_GT(r.msMedian, 0.0) << render::rooflineKernelName(r.kernel);
    EXPECT_GT(r.msEmptyMedian, 0.0) << render::rooflineKernelName(r.kernel);
    EXPECT_TRUE(std::isfinite(r.fetchesPerSecond) && r.fetchesPerSecond >= 0.0)
        << render::rooflineKernelName(r.kernel);
  }
  EXPECT_EQ(kernels.size(), 6u);
}

TEST(Roofline, RefusesNoFetches) {
  EXPECT_THROW(render::measureRoofline(test::gpuContext(), {.fetchesPerFragment = 0}), InputError);
}
