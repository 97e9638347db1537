#pragma once
// The volumes a user opened last in the desktop viewer, newest first, kept
// between sessions in a small JSON file in the user's configuration folder:
//   {"recent": ["/data/ch2.nii.gz", "/data/ct/series", ...]}
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace tessera::viewer {

class RecentFiles {
 public:
  static constexpr std::size_t kMaxEntries = 10;

  // $XDG_CONFIG_HOME/tessera/recent-files.json, else
  // $HOME/.config/tessera/recent-files.json (the XDG default); empty when
  // neither variable is set (nothing is remembered then).
  static std::filesystem::path defaultPath();

  explicit RecentFiles(std::filesystem::path file) : file_(std::move(file)) {}
  const std::filesystem::path& path() const { return file_; }
  const std::vector<std::string>& entries() const { return entries_; }

  // Reads the file; a missing file is an empty list. InputError naming the
  // file when it is not such a JSON file (the list stays empty).
  void load();
  // Puts `entry` first (moving it if listed), keeps kMaxEntries, and saves.
  void add(const std::string& entry);
  // Drops `entry` (e.g. a file that no longer opens) and saves.
  void remove(const std::string& entry);

 private:
  // Writes through a temporary file renamed into place, creating the folder;
  // InputError naming the file on failure.
  void save() const;

  std::filesystem::path file_;
  std::vector<std::string> entries_;
};

}  // namespace tessera::viewer
