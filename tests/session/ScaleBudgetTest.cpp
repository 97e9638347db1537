// A virtual 4096^3 u16 head (head16:4096: 128 GiB, computed brick by
// brick, never held) renders through bricks under the webgl2 and ipad2
// profiles within their budgets: the ledger's texture peak under the
// profile's texture budget, the process's peak RSS under the host budget,
// a few MiB generated, and the refined image against the CPU reference of
// the level it shows. The full table (512^3 .. 8192^3 at 512²) is
// `tessera bench --scale` (docs/large-data.md "Scale").
#include <gtest/gtest.h>
#include <sys/resource.h>

#include "tessera/core/HostBudget.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/session/Session.h"

namespace tessera::session {
namespace {

std::uint64_t peakRssBytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<std::uint64_t>(u.ru_maxrss) * 1024;  // Linux: KiB
}

class ScaleBudget : public testing::TestWithParam<const char*> {};

TEST_P(ScaleBudget, A4096CubedU16HeadRendersWithinTheProfilesBudgets) {
  Session s(GetParam());
  s.settings().layout = "bricks";
  s.settings().tf = TransferFunction::fromPresetOrFile("ct-bone");
  // Half a voxel of the level a pixel resolves (4096 / 64 level-0 voxels,
  // capped at 8), and 32^3 empty-space blocks (a 128^3 grid), as the bench.
  s.settings().render.stepVoxels = 8.0;
  s.settings().skipBlock = 32;
  s.open("head16:4096");
  ASSERT_TRUE(s.streamed());
  RenderRequest r;
  r.settings = s.settings();
  r.width = r.height = 64;
  r.reference = true;
  const RenderResult result = s.run(r);
  ASSERT_TRUE(result.bricks.has_value());
  EXPECT_TRUE(result.bricks->complete);
  const gpu::DeviceSession& d = s.device();
  const std::uint64_t peak = d.context->ledger().peakBytes();
  EXPECT_GT(peak, 0u);
  EXPECT_LE(peak, d.limits.textureBudget) << GetParam();
  EXPECT_LE(peakRssBytes(), HostBudget::global().limitBytes()) << GetParam();
  EXPECT_LE(result.bricks->bytesRead, 64ull << 20) << "of 128 GiB";
  ASSERT_TRUE(result.psnrDb.has_value());
  EXPECT_GE(*result.psnrDb, 40.0) << "against the reference of the level shown";
  std::printf("%s: texture peak %s of %s, RSS peak %s of %s, %llu bricks (%s), %.1f dB\n",
              GetParam(), formatBytes(peak).c_str(), formatBytes(d.limits.textureBudget).c_str(),
              formatBytes(peakRssBytes()).c_str(),
              formatBytes(HostBudget::global().limitBytes()).c_str(),
              static_cast<unsigned long long>(result.bricks->bricksRead),
              formatBytes(result.bricks->bytesRead).c_str(), *result.psnrDb);
}

// ipad2 first: ru_maxrss is the process's, and ctest runs each case alone anyway.
INSTANTIATE_TEST_SUITE_P(Profiles, ScaleBudget, testing::Values("ipad2", "webgl2"));

}  // namespace
}  // namespace tessera::session
