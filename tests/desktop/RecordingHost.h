#pragma once
// The window's side of the panels (desktop::PanelHost) in a test: the
// error line kept, the files the panels asked to open recorded (and opened
// as the desktop's Open does: the volume to explore in the view, a store's
// channels together), overlay changes counted.
#include <string>
#include <vector>

#include "desktop/Panels.h"
#include "tessera/session/Session.h"

namespace tessera::test {

class RecordingHost : public desktop::PanelHost {
 public:
  explicit RecordingHost(session::Session& session) : session_(session) {}
  void setError(const std::string& message) override { error = message; }
  void openFile(const std::string& path) override {
    opened.push_back(path);
    session_.openInView(path);
    session_.channelView().open(path);
  }
  void overlayChanged() override { ++overlayChanges; }

  std::string error;
  std::vector<std::string> opened;
  int overlayChanges = 0;

 private:
  session::Session& session_;
};

}  // namespace tessera::test
