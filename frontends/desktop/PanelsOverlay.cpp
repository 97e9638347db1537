// The overlay panel: a second volume over the first (docs/fusion.md), as
// `tessera view --overlay` opens it: a file, labels with a table or a colour
// map, alpha and window; and the offer made for a file dropped while a
// volume is open (replace it, or add it as the overlay). The session opens,
// restyles and clears it through session/OverlayPanel.h (the calls a test
// drives: tests/session/OverlayPanelTest.cpp); the 3D view
// fuses it and the slice views mix it in (session::fuseSliceImage).
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "DesktopApp.h"
#include "tessera/session/OverlayPanel.h"

namespace tessera::desktop {

namespace {

constexpr const char* kDropOffer = "A second volume";

// The slice views show the overlay mixed in: drawn again.
void overlayChanged(DesktopApp& ds) {
  for (auto& tile : ds.slices) tile.key.clear();
}

// The panel's actions are session/OverlayPanel.h's, with the controls as
// they are (a test drives the same calls).
session::OverlayControls& controlsOf(DesktopApp& ds) {
  session::OverlayControls& c = ds.overlayUi.controls;
  c.table = ds.overlayUi.table;
  return c;
}

void addOverlay(DesktopApp& ds, const std::string& path) {
  reportErrors(ds, [&] {
    session::addOverlayFromPanel(*ds.session, path, controlsOf(ds));
    overlayChanged(ds);
  });
}

void restyle(DesktopApp& ds) {
  reportErrors(ds, [&] {
    if (session::restyleOverlayFromPanel(*ds.session, controlsOf(ds))) overlayChanged(ds);
  });
}

// The controls from an overlay opened elsewhere (--overlay, a state).
void syncControls(DesktopApp::OverlayControls& ui, const session::Overlay& o) {
  session::syncOverlayControls(ui.controls, o);
  std::snprintf(ui.table, sizeof ui.table, "%s", ui.controls.table.c_str());
}

void overlayInfo(const session::Overlay& o, const viewer::Viewer& v) {
  ImGui::TextWrapped("%s", session::overlayPanelLine(o).c_str());
  if (!o.note.empty()) ImGui::TextWrapped("%s", o.note.c_str());
  if (!v.fusionNote().empty()) ImGui::TextWrapped("3D view: %s", v.fusionNote().c_str());
}

// The colour maps' names for ImGui's combo.
bool colourMapCombo(int& chosen) {
  std::vector<const char*> names;
  for (const std::string& m : session::overlayColourMaps()) names.push_back(m.c_str());
  return ImGui::Combo("colour map", &chosen, names.data(), static_cast<int>(names.size()));
}

}  // namespace

void panelOverlay(DesktopApp& ds) {
  DesktopApp::OverlayControls& ui = ds.overlayUi;
  session::OverlayControls& c = ui.controls;
  section("Overlay (a second volume)");
  const session::Overlay* o = ds.session->overlay();
  if (o && o != ui.synced) {
    syncControls(ui, *o);
    ui.synced = o;
  }
  ImGui::InputText("##overlaypath", ui.path, sizeof ui.path);
  ImGui::SameLine();
  if (ImGui::Button("Add overlay") && ui.path[0]) addOverlay(ds, ui.path);
  bool changed = ImGui::Checkbox("labels (atlas)", &c.labels);
  if (c.labels) {
    ImGui::InputText("##overlaytable", ui.table, sizeof ui.table);
    ImGui::SameLine();
    changed |= ImGui::Button("table");
  } else {
    changed |= colourMapCombo(c.colourMap);
    changed |= ImGui::Checkbox("window", &c.window);
    if (c.window) {
      ImGui::SameLine();
      ImGui::SetNextItemWidth(160.0f);
      changed |= ImGui::InputDouble("##lo", &c.lo, 0.0, 0.0, "%g");
      ImGui::SameLine();
      ImGui::SetNextItemWidth(160.0f);
      changed |= ImGui::InputDouble("##hi", &c.hi, 0.0, 0.0, "%g");
    }
  }
  changed |= ImGui::SliderFloat("alpha", &c.alpha, 0.05f, 1.0f, "%.2f");
  if (changed) restyle(ds);
  if (!o) {
    ImGui::TextDisabled("none; or drop a file on the window while a volume is open");
    return;
  }
  overlayInfo(*o, ds.view());
  if (ImGui::Button("Remove overlay")) {
    session::removeOverlayFromPanel(*ds.session);
    ui.synced = nullptr;
    overlayChanged(ds);
  }
}

void offerDrop(DesktopApp& ds, const std::string& path) {
  if (!ds.session->hasVolume() || ds.session->name().rfind("gen:", 0) == 0) {
    openVolume(ds, path);
    return;
  }
  ds.overlayUi.dropped = path;
}

void drawDropOffer(DesktopApp& ds) {
  std::string& dropped = ds.overlayUi.dropped;
  if (dropped.empty()) return;
  if (!ImGui::IsPopupOpen(kDropOffer)) ImGui::OpenPopup(kDropOffer);
  if (!ImGui::BeginPopupModal(kDropOffer, nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return;
  const std::string file = std::filesystem::path(dropped).filename().string();
  const std::string open = std::filesystem::path(ds.session->name()).filename().string();
  ImGui::Text("%s is open. %s: add it over %s as an overlay, or replace %s?", open.c_str(),
              file.c_str(), open.c_str(), open.c_str());
  std::string chosen;
  if (ImGui::Button("Add as overlay")) chosen = "overlay";
  ImGui::SameLine();
  if (ImGui::Button("Replace")) chosen = "replace";
  ImGui::SameLine();
  if (ImGui::Button("Cancel")) chosen = "cancel";
  if (!chosen.empty()) {
    const std::string path = dropped;
    dropped.clear();
    ImGui::CloseCurrentPopup();
    if (chosen == "overlay") {
      std::snprintf(ds.overlayUi.path, sizeof ds.overlayUi.path, "%s", path.c_str());
      addOverlay(ds, path);
    } else if (chosen == "replace") {
      openVolume(ds, path);
    }
  }
  ImGui::EndPopup();
}

}  // namespace tessera::desktop
