// Files dropped on the window: GLFW's drop callback (gpu::GlfwWindow::onDrop)
// hands the paths over while the window's events run, and the frame after
// them opens or offers them (DesktopApp.cpp's runFrame): one path as
// offerDrop says (opened on an empty window, offered over an open volume),
// two as a volume and its overlay. tests/desktop/PanelsDropTest.cpp calls
// the callback's function with path lists.
#include <filesystem>
#include <string>
#include <vector>

#include "Panels.h"

namespace tessera::desktop {

void filesDropped(OverlayUi& ui, const std::vector<std::string>& paths) {
  ui.pendingDrops.insert(ui.pendingDrops.end(), paths.begin(), paths.end());
}

void handleDrops(session::Session& s, OverlayUi& ui, PanelHost& host) {
  if (ui.pendingDrops.empty()) return;
  const std::vector<std::string> paths = std::move(ui.pendingDrops);
  ui.pendingDrops.clear();
  if (paths.size() == 1) {
    offerDrop(s, ui, host, paths[0]);
    return;
  }
  // Two files at once are a volume and its overlay: the first replaces
  // what is shown, the second is offered over it once it opened (the open
  // error, naming the first, is on the error line otherwise).
  host.openFile(paths[0]);
  if (!s.hasVolume() || s.name() != paths[0]) return;
  ui.dropped = paths[1];
  if (paths.size() == 2) return;
  std::string rest;
  for (std::size_t i = 2; i < paths.size(); ++i) {
    rest += (i > 2 ? ", " : "") + std::filesystem::path(paths[i]).filename().string();
  }
  host.setError(std::to_string(paths.size()) +
                " files dropped: the first is opened and the second offered as its overlay; " +
                rest + " not opened");
}

}  // namespace tessera::desktop
