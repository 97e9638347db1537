// `tessera profiles` as scripts see it: JSON that parses and lists every
// built-in, a table, and a one-line error naming a bad profile file.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <array>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "support/CliRunner.h"

namespace {

using ProfilesRun = tessera::test::CliRun;
using tessera::test::countLines;
using tessera::test::runCli;

const std::set<std::string> kBuiltins = {
    "axim-x51v", "ipad2", "webgl1-desktop-2012", "nexus7", "shield-k1", "gles2", "webgl1", "gles3",
    "webgl2",    "native"};

}  // namespace

TEST(ProfilesCommand, JsonListsAllTenBuiltinsWithTheirFields) {
  const ProfilesRun r = runCli("profiles --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.is_array());
  std::set<std::string> names;
  for (const auto& p : j) {
    names.insert(p.at("name").get<std::string>());
    for (const char* key :
         {"note", "api", "max_2d_texture_size", "max_3d_texture_size", "texture_units",
          "texture_budget_mb", "host_budget_mb", "float_render_targets"}) {
      EXPECT_TRUE(p.contains(key)) << p.dump() << " lacks " << key;
    }
    EXPECT_FALSE(p.at("note").get<std::string>().empty()) << p.dump();
  }
  EXPECT_EQ(j.size(), 10u);
  EXPECT_EQ(names, kBuiltins);
  // Spot-check one row against the paper (Noguera & Jiménez 2012, iPad 2).
  for (const auto& p : j) {
    if (p["name"] != "ipad2") continue;
    EXPECT_EQ(p["api"], "gles2");
    EXPECT_EQ(p["max_2d_texture_size"], 2048);
    EXPECT_EQ(p["max_3d_texture_size"], 0);
    EXPECT_EQ(p["texture_units"], 8);
    EXPECT_EQ(p["texture_budget_mb"], 128);
  }
}

TEST(ProfilesCommand, TableHasAHeaderAndOneLinePerBuiltin) {
  const ProfilesRun r = runCli("profiles");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(countLines(r.out), 11) << r.out;
  EXPECT_EQ(r.out.rfind("name", 0), 0u) << r.out;
  for (const std::string& name : kBuiltins) {
    EXPECT_NE(r.out.find("\n" + name + " "), std::string::npos) << name << "\n" << r.out;
  }
  EXPECT_NE(r.out.find("16 MiB"), std::string::npos) << r.out;  // axim-x51v, via formatBytes
}

TEST(ProfilesCommand, ValidFileIsPrintedAsOneProfile) {
  const tessera::test::TempDir tmp;
  const auto path = tmp / "tablet.json";
  std::ofstream(path) << R"({"name": "tablet", "note": "test", "api": "gles2",
                            "max_2d_texture_size": 4096, "texture_units": 8,
                            "texture_budget_mb": 64})";
  const ProfilesRun r = runCli("profiles --json " + path.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["name"], "tablet");
  EXPECT_EQ(j["max_2d_texture_size"], 4096);
  EXPECT_EQ(j["max_3d_texture_size"], 0);
  EXPECT_EQ(j["texture_units"], 8);
  EXPECT_EQ(j["texture_budget_mb"], 64);
  EXPECT_EQ(j["host_budget_mb"], 0);
  EXPECT_EQ(j["float_render_targets"], false);
}

TEST(ProfilesCommand, BadFileFailsWithOneLineNamingIt) {
  const tessera::test::TempDir tmp;
  const auto bad = tmp / "bad.json";
  std::ofstream(bad) << R"({"name": "x", "api": "gles2", "max_3d_texture_size": 256})";
  const auto broken = tmp / "broken.json";
  std::ofstream(broken) << R"({"name": "x", "api": )";
  for (const std::string& file : {bad.string(), broken.string(), (tmp / "missing.json").string()}) {
    const ProfilesRun r = runCli("profiles " + file);
    EXPECT_NE(r.exitCode, 0) << file;
    EXPECT_EQ(countLines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}
