// `tessera render --lattice fcc [--density same|half]` as scripts see it.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/CliRunner.h"

using tessera::test::countLines;
using tessera::test::runCli;

TEST(FccCommand, RendersBothDensitiesAndComparesWithTheBoxSplineReference) {
  for (const char* density : {"same", "half"}) {
    const auto r = runCli(std::string("render gen:marschner-lobb:24 --lattice fcc --density ") +
                          density + " --size 48x48 --reference --json --out /dev/null");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["layout"], std::string(density) == "same" ? "fcc" : "fcc-half");
    EXPECT_EQ(j["lattice"], "fcc");
    EXPECT_GE(j["psnr_db"].get<double>(), 40.0) << density;
    // The lattice's texture: the unit cubes (origins -2 .. D) of a 30^3 grid
    // (same) or 24^3 (half), RGBA32F.
    const std::uint64_t cubes = std::string(density) == "same" ? 33u * 33 * 33 : 27u * 27 * 27;
    EXPECT_EQ(j["volume_texture_bytes"].get<std::uint64_t>(), cubes * 16) << density;
  }
}

TEST(FccCommand, BadLatticeOptionsFailWithOneLineNamingTheChoices) {
  struct Case {
    const char* args;
    const char* says;
  };
  for (const Case& c :
       {Case{"--lattice bcc", "expected cartesian or fcc"},
        Case{"--lattice fcc --density double", "same"}, Case{"--density half", "--lattice fcc"},
        Case{"--lattice fcc --layout mosaic", "does not combine"},
        Case{"--lattice fcc --profile gles2", "3D textures"},
        Case{"--lattice fcc --technique slice2d", "samples the layout"}}) {
    const auto r =
        runCli(std::string("render gen:sphere:16 --size 16x16 --out /dev/null ") + c.args);
    EXPECT_NE(r.exitCode, 0) << c.args;
    EXPECT_EQ(countLines(r.err), 1) << c.args << ": " << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << c.args << ": " << r.err;
  }
}
