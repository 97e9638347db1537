// `tessera plan` and `tessera render --profile/--layout` as scripts see them.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/CliRunner.h"

using tessera::test::countLines;
using tessera::test::runCli;
using tessera::test::runCliJson;

TEST(PlanCommand, Ipad2PacksAndSaysWhyTheOthersDoNotFit) {
  const auto j = runCliJson("plan gen:shepp-logan:181x217x181 --profile ipad2 --json");
  EXPECT_EQ(j["layout"], "packed-mosaic");
  EXPECT_EQ(j["profile"], "ipad2");
  EXPECT_EQ(j["limits"]["api"], "gles2");
  EXPECT_EQ(j["downsample"], nlohmann::json({1, 1, 1}));
  ASSERT_EQ(j["rejected"].size(), 2u);
  EXPECT_EQ(j["rejected"][0]["layout"], "texture3d");
  EXPECT_EQ(j["rejected"][1]["layout"], "mosaic");
  EXPECT_FALSE(j["reason"].get<std::string>().empty());
  std::uint64_t sum = 0;
  for (const auto& t : j["plan"]["textures"]) sum += t["bytes"].get<std::uint64_t>();
  EXPECT_EQ(sum, j["plan"]["total_bytes"].get<std::uint64_t>());
}

TEST(PlanCommand, Webgl2UsesA3dTexture) {
  const auto j = runCliJson("plan gen:sphere:64x80x48 --profile webgl2 --json");
  EXPECT_EQ(j["layout"], "texture3d");
  EXPECT_EQ(j["plan"]["total_bytes"], 64 * 80 * 48);
}

TEST(PlanCommand, ImpossibleWishesFailWithOneLine) {
  for (const char* args :
       {"plan gen:sphere:32 --profile ipad2 --layout texture3d",
        "plan gen:sphere:32 --profile no-such-device", "plan gen:sphere:32 --layout no-such-layout",
        "render gen:sphere:32 --profile webgl1 --layout texture3d"}) {
    const auto r = runCli(args);
    EXPECT_NE(r.exitCode, 0) << args;
    EXPECT_EQ(countLines(r.err), 1) << args << ": " << r.err;
  }
}

TEST(PlanCommand, RenderOnAnEs2ProfileMatchesTheReference) {
  const auto j = runCliJson(
      "render gen:shepp-logan:48 --profile webgl1 --layout packed-mosaic --size 64x64 --tf bench "
      "--reference --json --out /dev/null");
  EXPECT_EQ(j["api"], "gles2");
  EXPECT_EQ(j["layout"], "packed-mosaic");
  EXPECT_GE(j["psnr_db"].get<double>(), 40.0);
  EXPECT_LE(j["texture_bytes"].get<std::uint64_t>(), j["texture_budget"].get<std::uint64_t>());
}
