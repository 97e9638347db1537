#pragma once
// The window's side of the panels (desktop::PanelHost) in a test: the
// error line kept, the files the panels asked to open recorded and opened
// by the desktop's own desktop::openVolume (the function DesktopApp's
// openFile calls: the volume to explore in the view, a store's channels
// together, the recent list), the window's notices counted.
#include <filesystem>
#include <string>
#include <vector>

#include "desktop/Panels.h"
#include "tessera/session/Session.h"

namespace tessera::test {

class RecordingHost : public desktop::PanelHost {
 public:
  // `recentFile`: where the recent list is kept (empty: in memory only).
  explicit RecordingHost(session::Session& session, std::filesystem::path recentFile = {})
      : files(std::move(recentFile)), session_(session) {}
  void setError(const std::string& message) override { error = message; }
  const std::string& errorLine() const override { return error; }
  void openFile(const std::string& path) override {
    opened.push_back(path);
    desktop::openVolume(session_, files, *this, path);
  }
  void overlayChanged() override { ++overlayChanges; }
  void viewChanged() override { ++viewChanges; }
  void stateLoaded() override { ++statesLoaded; }

  desktop::FileUi files;  // the file panel's (the desktop's ds.files)
  std::string error;
  std::vector<std::string> opened;
  int overlayChanges = 0;
  int viewChanges = 0;
  int statesLoaded = 0;

 private:
  session::Session& session_;
};

}  // namespace tessera::test
