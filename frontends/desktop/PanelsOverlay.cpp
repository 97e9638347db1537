// The overlay panel: a second volume over the first (docs/fusion.md), as
// `tessera view --overlay` opens it: a file, labels with a table or a colour
// map, alpha and window; and the offer made for a file dropped while a
// volume is open (replace it, or add it as the overlay). The session opens,
// restyles and clears it (Session::openOverlay / setOverlay); the 3D view
// fuses it and the slice views mix it in (session::fuseSliceImage).
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <string>

#include "DesktopApp.h"
#include "tessera/session/Fusion.h"

namespace tessera::desktop {

namespace {

constexpr const char* kColourMaps[] = {"hot", "grey", "mr-default", "ct-bone", "bench"};
constexpr const char* kDropOffer = "A second volume";

session::OverlayOptions optionsOf(const DesktopApp::OverlayControls& c) {
  session::OverlayOptions o;
  o.labels = c.labels;
  if (c.labels) o.labelTable = c.table;
  o.tf = kColourMaps[c.colourMap];
  o.opacity = c.alpha;
  if (c.window) o.window = ValueRange{c.lo, c.hi};
  return o;
}

// The slice views show the overlay mixed in: drawn again.
void overlayChanged(DesktopApp& ds) {
  for (auto& tile : ds.slices) tile.key.clear();
}

void addOverlay(DesktopApp& ds, const std::string& path) {
  reportErrors(ds, [&] {
    ds.session->openOverlay(path, optionsOf(ds.overlayUi));
    overlayChanged(ds);
  });
}

void restyle(DesktopApp& ds) {
  if (!ds.session->overlay()) return;
  reportErrors(ds, [&] {
    ds.session->restyleOpenOverlay(optionsOf(ds.overlayUi));
    overlayChanged(ds);
  });
}

// The controls from an overlay opened elsewhere (--overlay, a state).
void syncControls(DesktopApp::OverlayControls& c, const session::Overlay& o) {
  c.labels = o.options.labels;
  c.alpha = static_cast<float>(o.options.opacity);
  c.window = o.options.window.has_value();
  if (c.window) {
    c.lo = o.options.window->min;
    c.hi = o.options.window->max;
  }
}

void overlayInfo(const session::Overlay& o, const viewer::Viewer& v) {
  const glm::ivec3 d = o.fused->volume->dims();
  ImGui::TextWrapped("%s %dx%dx%d: %s", std::filesystem::path(o.name).filename().c_str(), d.x, d.y,
                     d.z,
                     o.fused->labels ? (std::to_string(o.labels.labels.size()) + " labels").c_str()
                                     : ("colour map " + o.options.tf).c_str());
  if (!o.note.empty()) ImGui::TextWrapped("%s", o.note.c_str());
  if (!v.fusionNote().empty()) ImGui::TextWrapped("3D view: %s", v.fusionNote().c_str());
}

}  // namespace

void panelOverlay(DesktopApp& ds) {
  DesktopApp::OverlayControls& c = ds.overlayUi;
  section("Overlay (a second volume)");
  const session::Overlay* o = ds.session->overlay();
  if (o && o != c.synced) {
    syncControls(c, *o);
    c.synced = o;
  }
  ImGui::InputText("##overlaypath", c.path, sizeof c.path);
  ImGui::SameLine();
  if (ImGui::Button("Add overlay") && c.path[0]) addOverlay(ds, c.path);
  bool changed = ImGui::Checkbox("labels (atlas)", &c.labels);
  if (c.labels) {
    ImGui::InputText("##overlaytable", c.table, sizeof c.table);
    ImGui::SameLine();
    changed |= ImGui::Button("table");
  } else {
    changed |= ImGui::Combo("colour map", &c.colourMap, kColourMaps,
                            static_cast<int>(std::size(kColourMaps)));
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
    ds.session->clearOverlay();
    c.synced = nullptr;
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
