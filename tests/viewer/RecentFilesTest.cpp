#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <optional>
#include <string>

#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/viewer/RecentFiles.h"

namespace tessera::viewer {
namespace {

// Sets an environment variable for the scope and restores it.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value) {
      ::setenv(name, value, 1);
    } else {
      ::unsetenv(name);
    }
  }
  ~ScopedEnv() {
    if (old_) {
      ::setenv(name_, old_->c_str(), 1);
    } else {
      ::unsetenv(name_);
    }
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

TEST(RecentFiles, NewestFirstWithoutDuplicatesKeepsTenAndPersists) {
  test::TempDir dir;
  const auto file = dir / "config" / "tessera" / "recent-files.json";
  RecentFiles recent(file);
  recent.load();
  EXPECT_TRUE(recent.entries().empty());
  for (int i = 0; i < 12; ++i) recent.add("/data/v" + std::to_string(i) + ".nii.gz");
  ASSERT_EQ(recent.entries().size(), RecentFiles::kMaxEntries);
  EXPECT_EQ(recent.entries().front(), "/data/v11.nii.gz");
  EXPECT_EQ(recent.entries().back(), "/data/v2.nii.gz");
  recent.add("/data/v5.nii.gz");  // reopened: moves to the front
  EXPECT_EQ(recent.entries().front(), "/data/v5.nii.gz");
  EXPECT_EQ(recent.entries().size(), RecentFiles::kMaxEntries);
  recent.remove("/data/v9.nii.gz");

  RecentFiles again(file);
  again.load();
  EXPECT_EQ(again.entries(), recent.entries());
  EXPECT_EQ(again.entries().size(), RecentFiles::kMaxEntries - 1);
}

TEST(RecentFiles, ACorruptListNamesItsFile) {
  test::TempDir dir;
  const auto file = dir / "recent-files.json";
  std::ofstream(file) << "{\"recent\": 3";
  RecentFiles recent(file);
  try {
    recent.load();
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
  }
  EXPECT_TRUE(recent.entries().empty());
  recent.add("/data/head.nii");  // replaces it
  RecentFiles again(file);
  again.load();
  ASSERT_EQ(again.entries().size(), 1u);
}

TEST(RecentFiles, LivesInXdgConfigHomeElseHomeDotConfig) {
  {
    const ScopedEnv xdg("XDG_CONFIG_HOME", "/tmp/xdg-config");
    EXPECT_EQ(RecentFiles::defaultPath(), "/tmp/xdg-config/tessera/recent-files.json");
  }
  const ScopedEnv xdg("XDG_CONFIG_HOME", nullptr);
  const ScopedEnv home("HOME", "/home/someone");
  EXPECT_EQ(RecentFiles::defaultPath(), "/home/someone/.config/tessera/recent-files.json");
  const ScopedEnv relative("XDG_CONFIG_HOME", "relative/dir");  // ignored, as the spec says
  EXPECT_EQ(RecentFiles::defaultPath(), "/home/someone/.config/tessera/recent-files.json");
}

}  // namespace
}  // namespace tessera::viewer
