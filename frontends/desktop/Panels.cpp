// What the window-free panels (Panels.h) share.
#include "Panels.h"

namespace tessera::desktop {

void beginControlPanel(float height) {
  ImGui::SetNextWindowPos(ImVec2(0, 0));
  ImGui::SetNextWindowSize(ImVec2(kPanelWidth, height));
  ImGui::Begin(kPanelTitle, nullptr,
               ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
}

void section(const char* title) {
  ImGui::Spacing();
  ImGui::Separator();
  ImGui::TextUnformatted(title);
}

}  // namespace tessera::desktop
