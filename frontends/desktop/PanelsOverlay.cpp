// The overlay panel: a second volume over the first (docs/fusion.md), as
// `tessera view --overlay` opens it: a file, labels with a table or a colour
// map, alpha and window; and the offer made for a file dropped while a
// volume is open (replace it, or add it as the overlay). The session opens,
// restyles and clears it through session/OverlayPanel.h; the 3D view fuses
// it and the slice views mix it in (session::fuseSliceImage).
// tests/desktop/PanelsOverlayTest.cpp clicks these widgets without a window.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "Panels.h"
#include "tessera/session/OverlayPanel.h"
#include "tessera/session/Session.h"

namespace tessera::desktop {

namespace {

// The panel's actions are session/OverlayPanel.h's, with the controls as
// they are.
session::OverlayControls& controlsOf(OverlayUi& ui) {
  session::OverlayControls& c = ui.controls;
  c.table = ui.table;
  return c;
}

void addOverlay(session::Session& s, OverlayUi& ui, PanelHost& host, const std::string& path) {
  reportErrors(host, [&] {
    session::addOverlayFromPanel(s, path, controlsOf(ui));
    host.overlayChanged();
  });
}

void restyle(session::Session& s, OverlayUi& ui, PanelHost& host) {
  reportErrors(host, [&] {
    if (session::restyleOverlayFromPanel(s, controlsOf(ui))) host.overlayChanged();
  });
}

// The controls from an overlay opened elsewhere (--overlay, a state).
void syncControls(OverlayUi& ui, const session::Overlay& o) {
  session::syncOverlayControls(ui.controls, o);
  std::snprintf(ui.table, sizeof ui.table, "%s", ui.controls.table.c_str());
}

void overlayInfo(const session::Overlay& o, session::Session& s) {
  ImGui::TextWrapped("%s", session::overlayPanelLine(o).c_str());
  if (!o.note.empty()) ImGui::TextWrapped("%s", o.note.c_str());
  if (s.hasView() && !s.view().fusionNote().empty()) {
    ImGui::TextWrapped("3D view: %s", s.view().fusionNote().c_str());
  }
}

// The colour maps' names for ImGui's combo.
bool colourMapCombo(int& chosen) {
  std::vector<const char*> names;
  for (const std::string& m : session::overlayColourMaps()) names.push_back(m.c_str());
  return ImGui::Combo("colour map", &chosen, names.data(), static_cast<int>(names.size()));
}

// The look's controls; true when one changed.
bool lookControls(OverlayUi& ui) {
  session::OverlayControls& c = ui.controls;
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
  return changed;
}

}  // namespace

void panelOverlay(session::Session& s, OverlayUi& ui, PanelHost& host) {
  section("Overlay (a second volume)");
  const session::Overlay* o = s.overlay();
  if (o && o != ui.synced) {
    syncControls(ui, *o);
    ui.synced = o;
  }
  ImGui::InputText("##overlaypath", ui.path, sizeof ui.path);
  ImGui::SameLine();
  if (ImGui::Button("Add overlay") && ui.path[0]) addOverlay(s, ui, host, ui.path);
  if (lookControls(ui)) restyle(s, ui, host);
  o = s.overlay();  // the one added or restyled now
  if (!o) {
    ImGui::TextDisabled("none; or drop a file on the window while a volume is open");
    return;
  }
  overlayInfo(*o, s);
  if (ImGui::Button("Remove overlay")) {
    session::removeOverlayFromPanel(s);
    ui.synced = nullptr;
    host.overlayChanged();
  }
}

void offerDrop(session::Session& s, OverlayUi& ui, PanelHost& host, const std::string& path) {
  if (!s.hasVolume() || s.name().rfind("gen:", 0) == 0) {
    host.openFile(path);
    return;
  }
  ui.dropped = path;
}

void drawDropOffer(session::Session& s, OverlayUi& ui, PanelHost& host) {
  std::string& dropped = ui.dropped;
  if (dropped.empty()) return;
  if (!ImGui::IsPopupOpen(kDropOfferTitle)) ImGui::OpenPopup(kDropOfferTitle);
  if (!ImGui::BeginPopupModal(kDropOfferTitle, nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return;
  const std::string file = std::filesystem::path(dropped).filename().string();
  const std::string open = std::filesystem::path(s.name()).filename().string();
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
      std::snprintf(ui.path, sizeof ui.path, "%s", path.c_str());
      addOverlay(s, ui, host, path);
    } else if (chosen == "replace") {
      host.openFile(path);
    }
  }
  ImGui::EndPopup();
}

}  // namespace tessera::desktop
