// `tessera render --overlays ... --offscreen ...`: the hybrid
// compositor from the command line, with every technique, against the CPU
// ground truth (volume and lines at full resolution, rays stopped at lines).
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "support/CliRunner.h"

using tessera::test::expectFailure;
using tessera::test::runCli;

namespace {

nlohmann::json renderHybrid(const std::string& technique, const std::string& offscreen,
                            const std::string& overlays) {
  const auto r = runCli("render gen:shepp-logan:48 --technique " + technique +
                        " --size 96x128 --overlays " + overlays + " --offscreen " + offscreen +
                        " --ert 1 --reference --json --out /dev/null");
  EXPECT_EQ(r.exitCode, 0) << r.err;
  return nlohmann::json::parse(r.out);
}

}  // namespace

TEST(HybridCommand, EveryTechniqueMatchesTheGroundTruth) {
  for (const char* technique : {"raycast", "slice3d", "slice2d"}) {
    // At full resolution only the lines' occlusion and the technique's own
    // error separate the image from the ground truth.
    const auto full = renderHybrid(technique, "full", "box");
    EXPECT_EQ(full["technique"], technique);
    EXPECT_EQ(full["volume_target"], nlohmann::json::array({96, 128}));
    EXPECT_GE(full["psnr_db"].get<double>(), 38.0) << technique;
    // A 48x48 target (2304 pixels) is rendered by the slicers in the
    // screen's 3:4 shape with about as many pixels; upscaling costs detail.
    const auto low = renderHybrid(technique, "48x48", "box,axes");
    const auto target = low["volume_target"];
    const int pixels = target[0].get<int>() * target[1].get<int>();
    EXPECT_NEAR(pixels, 48 * 48, 48 * 48 / 20) << technique << " " << target;
    EXPECT_GE(low["psnr_db"].get<double>(), 26.0) << technique;
    EXPECT_LT(low["psnr_db"].get<double>(), full["psnr_db"].get<double>()) << technique;
  }
}

TEST(HybridCommand, BadOptionsFailWithOneLine) {
  expectFailure("render gen:sphere:16 --line-attenuation foggy --out /dev/null",
                "--line-attenuation 'foggy'");
  // The option's name before --overlay-opacity became the fused volume's.
  expectFailure("render gen:sphere:16 --overlays box --overlay-opacity two-pass --out /dev/null",
                "--overlay-opacity two-pass: the attenuation of the --overlays lines is now "
                "--line-attenuation two-pass; --overlay-opacity is the --overlay volume's "
                "opacity, (0, 1]");
  expectFailure(
      "render gen:sphere:16 --overlay gen:sphere:16 --overlay-opacity 1.5 --out /dev/null",
      "--overlay-opacity '1.5': expected the overlay's opacity in (0, 1]");
  expectFailure("render gen:sphere:16 --overlays box --offscreen 0 --out /dev/null", "offscreen");
  expectFailure(
      "render gen:sphere:16 --technique slice2d --layout mosaic --overlays box --out /dev/null",
      "--layout does not apply to slice2d");
}
