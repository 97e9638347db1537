// `tessera profiles`: the built-in device profiles as a table or JSON, or one
// profile (a built-in name or a JSON file, validated) on its own.
#include <algorithm>
#include <array>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/Commands.h"
#include "tessera/core/HostBudget.h"
#include "tessera/gpu/DeviceProfile.h"

namespace tessera::app {

namespace {

struct ProfilesOptions {
  std::string profile;  // empty: all built-ins
  bool json = false;
};

std::string limitText(int value, const char* zero) {
  if (value >= gpu::DeviceProfile::kUnlimited) return "unlimited";
  if (value == 0) return zero;
  return std::to_string(value);
}

std::string budgetText(std::uint64_t bytes) {
  return bytes == 0 ? "unlimited" : formatBytes(bytes);
}

constexpr std::size_t kColumns = 8;
using Row = std::array<std::string, kColumns>;

Row rowOf(const gpu::DeviceProfile& p) {
  return {p.name,
          gpu::apiLevelName(p.api),
          limitText(p.max2DTextureSize, "none"),
          limitText(p.max3DTextureSize, "none"),
          limitText(p.textureUnits, "none"),
          budgetText(p.textureBudget),
          budgetText(p.hostBudget),
          p.note};
}

void printTable(const std::vector<gpu::DeviceProfile>& profiles) {
  std::vector<Row> rows = {
      {"name", "api", "max 2D", "max 3D", "units", "texture budget", "host budget", "note"}};
  for (const auto& p : profiles) rows.push_back(rowOf(p));
  std::array<std::size_t, kColumns> width{};
  for (const Row& r : rows) {
    for (std::size_t c = 0; c < kColumns; ++c) width[c] = std::max(width[c], r[c].size());
  }
  for (const Row& r : rows) {
    std::string line;
    for (std::size_t c = 0; c + 1 < kColumns; ++c) {
      line += r[c] + std::string(width[c] - r[c].size() + 2, ' ');
    }
    line += r[kColumns - 1];  // the note: last, unpadded, never cut
    std::printf("%s\n", line.c_str());
  }
}

void runProfiles(const ProfilesOptions& o) {
  std::vector<gpu::DeviceProfile> profiles;
  if (o.profile.empty()) {
    profiles = gpu::DeviceProfile::builtins();
  } else {
    profiles.push_back(gpu::DeviceProfile::find(o.profile));  // InputError names the file
  }
  if (o.json) {
    // One profile prints as an object (the file format); the list as an array.
    if (!o.profile.empty()) {
      std::printf("%s\n", profiles.front().toJson().c_str());
      return;
    }
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const auto& p : profiles) list.push_back(nlohmann::ordered_json::parse(p.toJson()));
    std::printf("%s\n", list.dump(2).c_str());
    return;
  }
  printTable(profiles);
}

}  // namespace

void addProfilesCommand(CLI::App& app) {
  auto opts = std::make_shared<ProfilesOptions>();
  CLI::App* cmd = app.add_subcommand(
      "profiles", "List the built-in device profiles, or validate and print one profile");
  cmd->add_option("profile", opts->profile,
                  "A built-in profile name or a profile .json file to validate; default: list "
                  "the built-ins");
  cmd->add_flag("--json", opts->json, "Print JSON (an array, or one object for one profile)");
  cmd->callback([opts] { runProfiles(*opts); });
}

}  // namespace tessera::app
