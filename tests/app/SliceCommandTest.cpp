// `tessera render --technique slice3d|slice2d`: the CLI reaches
// the slicing techniques, reports them, and their images match the reference.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/CliRunner.h"

using tessera::test::expectFailure;
using tessera::test::runCli;
using tessera::test::runCliJson;

TEST(SliceCommand, Slice3dOnAnEs2ProfileMatchesTheReference) {
  const auto j = runCliJson(
      "render gen:shepp-logan:48 --technique slice3d --profile webgl1 --size 64x64 --tf bench "
      "--ert 1 --reference --json --out /dev/null");
  EXPECT_EQ(j["technique"], "slice3d");
  EXPECT_EQ(j["api"], "gles2");
  EXPECT_NE(j["layout"], "texture3d");
  EXPECT_GE(j["psnr_db"].get<double>(), 30.0);
  // The ledger's count while the slicer lives: the volume plus its own TF
  // table, proxy VBO and accumulation target.
  EXPECT_GT(j["texture_bytes"].get<std::uint64_t>(),
            j["volume_texture_bytes"].get<std::uint64_t>());
}

TEST(SliceCommand, Slice2dEveryClassificationMatchesTheReference) {
  for (const char* cls : {"pre", "palette", "post"}) {
    const auto r =
        runCli(std::string("render gen:sphere:40 --technique slice2d --classify ") + cls +
               " --size 64x64 --tf bench --ert 1 --reference --json --out /dev/null");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["layout"], "slice-stacks");
    EXPECT_GE(j["psnr_db"].get<double>(), 30.0) << cls;
    EXPECT_GT(j["volume_texture_bytes"].get<std::uint64_t>(), 0u) << cls;
    EXPECT_GT(j["texture_bytes"].get<std::uint64_t>(),
              j["volume_texture_bytes"].get<std::uint64_t>())
        << cls;
  }
}

TEST(SliceCommand, BadTechniqueOrClassificationFailsWithOneLine) {
  expectFailure("render gen:sphere:16 --technique splat --out /dev/null",
                "technique 'splat': expected raycast");
  expectFailure("render gen:sphere:16 --technique slice2d --classify later --out /dev/null",
                "classify 'later'");
}
