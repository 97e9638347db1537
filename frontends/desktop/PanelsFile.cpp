// The file panel: a path to open, the recent volumes (Ctrl+1..9 in
// Input.cpp), the session's state saved and loaded, and the panel's error
// line; and what opening a volume means in the desktop viewer (the file
// panel's Open, a recent volume, a dropped file, the command line's file):
// the session opens it to explore in the view, the recent list remembers it.
// tests/desktop/PanelsFileTest.cpp clicks these widgets without a window.
#include <filesystem>
#include <string>

#include "Panels.h"
#include "tessera/lod/ProceduralMultiresSource.h"

namespace tessera::desktop {

namespace {

bool generated(const std::string& spec) {
  return spec.rfind("gen:", 0) == 0 || lod::ProceduralMultiresSource::isSpec(spec);
}

// Files and folders (not generated volumes) go to the recent list, by their
// absolute path; one that cannot be opened because it is gone leaves it.
void rememberOpened(FileUi& ui, PanelHost& host, const std::string& spec) {
  if (generated(spec)) return;
  reportErrors(host, [&] {
    std::error_code ec;
    const std::filesystem::path full = std::filesystem::absolute(spec, ec);
    ui.recent.add(ec ? spec : full.lexically_normal().string());
  });
}

void forgetIfGone(FileUi& ui, const std::string& spec) {
  std::error_code ec;
  if (std::filesystem::exists(spec, ec)) return;
  try {
    ui.recent.remove(spec);
  } catch (const Error&) {
    // The list could not be rewritten: the open error already says more.
  }
}

void recentCombo(session::Session& s, FileUi& ui, PanelHost& host) {
  if (ui.recent.entries().empty() || !ImGui::BeginCombo("recent", "open a recent volume")) return;
  std::string chosen;
  for (std::size_t i = 0; i < ui.recent.entries().size(); ++i) {
    const std::string& path = ui.recent.entries()[i];
    const std::string label = std::to_string(i + 1) + "  " +
                              std::filesystem::path(path).filename().string() + "##" + path;
    if (ImGui::Selectable(label.c_str())) chosen = path;
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", path.c_str());
  }
  ImGui::EndCombo();
  if (!chosen.empty()) openVolume(s, ui, host, chosen);
}

}  // namespace

session::OpenOptions FileUi::optionsFor(const std::string& spec) const {
  session::OpenOptions open;
  open.series = commandLine.series;
  if (spec == commandLineFile) {
    open.time = commandLine.time;
    open.channel = commandLine.channel;
  }
  return open;
}

// Shows the volume's overview, and a store's channels together when it has
// several and `channels` asks for them; an error is shown in the panel and
// the previous volume stays.
void openVolume(session::Session& s, FileUi& ui, PanelHost& host, const std::string& spec,
                bool channels) {
  try {
    s.openInView(spec, ui.optionsFor(spec));
    host.setError("");
  } catch (const Error& e) {
    host.setError(std::string(e.what()) + " (the previous volume stays)");
    forgetIfGone(ui, spec);
    return;
  }
  host.viewChanged();
  rememberOpened(ui, host, spec);
  if (channels) openChannels(s, ui, host, spec);
}

void openChannels(session::Session& s, const FileUi& ui, PanelHost& host, const std::string& spec) {
  // A series over bricks streams its channels together (the session's
  // streamed frames draw them); otherwise the list reads them in core.
  // --time chooses within the file given on the command line.
  const int time = ui.optionsFor(spec).time;
  reportErrors(host, [&] { s.channelView().open(spec, time); });
}

void panelFile(session::Session& s, FileUi& ui, PanelHost& host) {
  ImGui::TextWrapped("%s", s.view().description().c_str());
  ImGui::InputText("##path", ui.path, sizeof ui.path);
  ImGui::SameLine();
  if (ImGui::Button("Open") && ui.path[0]) openVolume(s, ui, host, ui.path);
  ImGui::TextDisabled("or drop a file on the window; F1: keyboard shortcuts");
  recentCombo(s, ui, host);
  // The session's state: camera, look, crosshair, region and grid.
  ImGui::InputText("##state", ui.statePath, sizeof ui.statePath);
  ImGui::SameLine();
  if (ImGui::Button("Save state")) reportErrors(host, [&] { s.saveState(ui.statePath); });
  ImGui::SameLine();
  if (ImGui::Button("Load")) {
    reportErrors(host, [&] {
      s.loadState(ui.statePath);
      host.stateLoaded();
    });
  }
  if (!host.errorLine().empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.45f, 0.4f, 1.0f));
    ImGui::TextWrapped("%s", host.errorLine().c_str());
    ImGui::PopStyleColor();
  }
}

}  // namespace tessera::desktop
