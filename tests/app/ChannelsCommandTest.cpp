// tessera render --channels: a 3-channel store's channels in one frame,
// through the CLI, against the CPU reference; bad channel options fail with
// one line naming the store or the option.
#include <gtest/gtest.h>

#include <string>

#include "support/ChannelStore.h"
#include "support/CliRunner.h"
#include "support/TestSupport.h"

using namespace tessera;

TEST(ChannelsCommand, RendersTheChosenChannelsLikeTheReference) {
  const test::TempDir dir;
  const std::string store = (dir / "three.ome.zarr").string();
  test::writeChannelStore(store, {.dims = {48, 48, 24}});
  for (const char* mode : {"additive", "max"}) {
    const nlohmann::json j = test::runCliJson(
        "render " + store + " --channels 0,2 --channel-colors ffff00,00ffff --channel-windows " +
        "100:3000,100:2000 --channel-mode " + mode + " --tf grey --opacity-scale 20 " +
        "--size 64x64 --reference --json --out " + (dir / "out.png").string());
    ASSERT_EQ(j["channels"].size(), 2u) << j;
    EXPECT_EQ(j["channels"][1].get<std::string>(), "rod 00ffff 100:2000 on");
    EXPECT_EQ(j["mode"], mode);
    EXPECT_GE(j["psnr_db"].get<double>(), 40.0) << mode;
  }
}

TEST(ChannelsCommand, BadChannelOptionsFailWithOneLine) {
  const test::TempDir dir;
  const std::string store = (dir / "three.ome.zarr").string();
  test::writeChannelStore(store, {.dims = {16, 16, 8}});
  test::expectFailure("render " + store + " --channels 0,5 --out /dev/null",
                      store + ": channel 5 is outside the store's 3 channels (0..2)");
  test::expectFailure("render " + store + " --channels 0,2 --channel-windows 1:2 --out /dev/null",
                      "channels: 1 windows for 2 channels chosen");
  test::expectFailure("render " + store + " --channel-mode sum --out /dev/null",
                      "channel mode 'sum': expected additive or max");
}

// --technique reaches the channel frame: slice3d and slice2d draw it
// (against the same reference, >= 40 dB); slice2d pre-classified is refused
// in one line naming it.
TEST(ChannelsCommand, SlicersDrawChannelsAndPreClassificationIsRefused) {
  const test::TempDir dir;
  const std::string store = (dir / "three.ome.zarr").string();
  test::writeChannelStore(store, {.dims = {48, 48, 24}});
  for (const char* technique : {"slice3d", "slice2d"}) {
    for (const char* mode : {"additive", "max"}) {
      const nlohmann::json j = test::runCliJson(
          "render " + store + " --channels 0,1,2 --channel-mode " + mode + " --technique " +
          technique + " --tf grey --opacity-scale 20 --size 64x64 --reference --json --out " +
          (dir / "out.png").string());
      EXPECT_EQ(j["mode"], mode);
      EXPECT_GE(j["psnr_db"].get<double>(), 40.0) << technique << " " << mode;
    }
  }
  test::expectFailure(
      "render " + store + " --channels 0,2 --technique slice2d --classify pre --out /dev/null",
      "slice2d draws channels post-classified (--classify post): pre and palette classify one "
      "volume's values");
}
