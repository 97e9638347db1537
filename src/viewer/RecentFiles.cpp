#include "tessera/viewer/RecentFiles.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <system_error>

#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"

namespace tessera::viewer {

std::filesystem::path RecentFiles::defaultPath() {
  const char* xdg = std::getenv("XDG_CONFIG_HOME");
  // The XDG base-directory spec: an empty or relative value is ignored.
  if (xdg && xdg[0] == '/') return std::filesystem::path(xdg) / "tessera" / "recent-files.json";
  const char* home = std::getenv("HOME");
  if (home && home[0] != '\0') {
    return std::filesystem::path(home) / ".config" / "tessera" / "recent-files.json";
  }
  return {};
}

void RecentFiles::load() {
  entries_.clear();
  if (file_.empty()) return;
  std::ifstream in(file_, std::ios::binary);
  if (!in) return;  // nothing remembered yet
  std::stringstream text;
  text << in.rdbuf();
  const nlohmann::json j = nlohmann::json::parse(text.str(), nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("recent") || !j["recent"].is_array()) {
    throw InputError(file_.string() +
                     ": not a recent-files list (expected {\"recent\": [\"path\", ...]}); "
                     "it is replaced when the next volume opens");
  }
  for (const nlohmann::json& e : j["recent"]) {
    if (e.is_string() && entries_.size() < kMaxEntries) entries_.push_back(e.get<std::string>());
  }
}

void RecentFiles::add(const std::string& entry) {
  if (entry.empty()) return;
  entries_.erase(std::remove(entries_.begin(), entries_.end(), entry), entries_.end());
  entries_.insert(entries_.begin(), entry);
  if (entries_.size() > kMaxEntries) entries_.resize(kMaxEntries);
  save();
}

void RecentFiles::remove(const std::string& entry) {
  const auto end = std::remove(entries_.begin(), entries_.end(), entry);
  if (end == entries_.end()) return;
  entries_.erase(end, entries_.end());
  save();
}

void RecentFiles::save() const {
  if (file_.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(file_.parent_path(), ec);
  if (ec) {
    throw InputError(file_.parent_path().string() +
                     ": cannot create the folder for the "
                     "recent-files list (" +
                     ec.message() + ")");
  }
  const std::filesystem::path temp = file_.string() + ".tmp";
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    out << nlohmann::json{{"recent", entries_}}.dump(2) << '\n';
    if (!out) throw InputError(temp.string() + ": cannot write the recent-files list");
  }
  std::filesystem::rename(temp, file_, ec);
  if (ec) {
    const std::string why = ec.message();
    std::filesystem::remove(temp, ec);
    throw InputError(file_.string() + ": cannot replace the recent-files list (" + why + ")");
  }
}

}  // namespace tessera::viewer
