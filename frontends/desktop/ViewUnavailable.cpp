// `tessera view` in a build without GLFW or Dear ImGui
// (cmake/DesktopViewer.cmake): the command exists and says what to do.
#include "ViewOptions.h"
#include "tessera/core/Error.h"

namespace tessera::desktop {

void runView(const ViewOptions&) {
  throw Error(
      "this tessera was built without the desktop viewer: install libglfw3-dev and "
      "libimgui-dev (scripts/setup.sh) and re-run cmake; or use the web viewer (scripts/web.sh)");
}

}  // namespace tessera::desktop
