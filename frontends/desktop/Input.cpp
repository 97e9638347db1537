// Input: the keyboard shortcuts (and the overlay that lists them), mouse
// gestures on the 3D view (orbit, pan, zoom, crop handles) and on the slice
// views (crosshair, region, slices). Keys are GLFW key codes, as Dear ImGui
// 1.86's GLFW backend reports them; every action is a viewer or exploring call.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "DesktopApp.h"
#include "tessera/render/TechniqueRegistry.h"

namespace tessera::desktop {

namespace {

// The keyboard shortcuts, as the help overlay lists them (handled in
// handleShortcuts; keys act only while no text field has the focus).
struct Shortcut {
  const char* keys;
  const char* action;
};
constexpr Shortcut kShortcuts[] = {
    {"F1 or ?", "show / hide this help"},
    {"Esc", "close this help"},
    {"R", "reset the view"},
    {"B", "bounding box on / off"},
    {"A", "axes on / off"},
    {"M", "composite / MIP"},
    {"Q", "adaptive / full quality"},
    {"T", "next technique"},
    {"Ctrl+1 ... Ctrl+9", "open recent volume 1 ... 9"},
    {"drag", "rotate (3D view)"},
    {"right-drag or Shift+drag", "pan (3D view)"},
    {"wheel", "zoom (3D view); next / previous slice (slice view)"},
    {"click / drag in a slice", "move the crosshair (all views)"},
    {"right-click / right-drag in a slice", "pick a region (box)"},
    {"Up / Down", "next / previous slice under the pointer"},
    {"[ / ]", "smaller / larger region"},
    {"V", "view the region at native resolution"},
    {"G", "grid view at native resolution"},
    {"arrows, PgUp / PgDn", "grid view: move back/forward, left/right, up/down"},
    {"O", "back to the overview"},
    {"L", "four views / 3D only"},
    {"C", "slices in grey / in the TF's colour"},
};

// A region from a right-drag in a slice view: the dragged rectangle in the
// slice's plane (a click: the default cube around the point), the region's
// side across it, centred on the slice; clamped to the budget and volume.
void pickRegion(DesktopApp& ds, const DesktopApp::SliceTile& tile, glm::dvec2 a, glm::dvec2 b) {
  const viewer::SliceGeometry& g = *tile.geometry;
  const int index = ds.exploration().explorer().crosshair()[g.axis()];
  const glm::ivec2 pa = tile.viewport.pixelAt(a);
  const glm::ivec2 pb = glm::length(b - a) < 4.0 ? pa : tile.viewport.pixelAt(b);
  ds.exploration().pick(ds.exploration().explorer().regionFromSlice(g, pa, pb, index));
}

// The crosshair `step` slices along the slice view's axis (its slice).
void stepSlice(DesktopApp& ds, const DesktopApp::SliceTile& tile, int step) {
  if (!tile.geometry) return;
  glm::ivec3 c = ds.exploration().explorer().crosshair();
  c[tile.geometry->axis()] += step;
  ds.exploration().explorer().setCrosshair(c);
}

// The slice view under the pointer (axial if none).
const DesktopApp::SliceTile& tileUnderPointer(const DesktopApp& ds, const Tiles& tiles) {
  const ImVec2 m = ImGui::GetIO().MousePos;
  int t = 0;
  for (int i = 0; i < 3; ++i) {
    if (tiles.slice[i].contains(m)) t = i;
  }
  return ds.slices[t];
}

// Typed letters act the same in either case (a non-ASCII character stays).
ImWchar lowerAscii(ImWchar c) {
  return c >= 'A' && c <= 'Z' ? static_cast<ImWchar>(c - 'A' + 'a') : c;
}

void nextTechnique(DesktopApp& ds) {
  const std::vector<std::string> names = render::TechniqueRegistry::global().names();
  const auto at = std::find(names.begin(), names.end(), ds.view().technique());
  const std::size_t next = at == names.end() ? 0 : (at - names.begin() + 1) % names.size();
  reportErrors(ds, [&] { ds.view().setTechnique(names[next]); });
}

// The typed-letter shortcuts of kShortcuts, either case; `exploring`: only
// with a volume to explore.
struct LetterKey {
  char letter;
  bool exploring;
  void (*act)(DesktopApp&);
};
constexpr LetterKey kLetterKeys[] = {
    {'?', false, [](DesktopApp& ds) { ds.showHelp = !ds.showHelp; }},
    {'r', false, [](DesktopApp& ds) { ds.view().resetCamera(); }},
    {'b', false, [](DesktopApp& ds) { ds.view().showBoundingBox = !ds.view().showBoundingBox; }},
    {'a', false, [](DesktopApp& ds) { ds.view().showAxes = !ds.view().showAxes; }},
    {'m', false,
     [](DesktopApp& ds) {
       RenderMode& mode = ds.view().settings().mode;
       mode = mode == RenderMode::Mip ? RenderMode::Composite : RenderMode::Mip;
     }},
    {'q', false,
     [](DesktopApp& ds) {
       viewer::Quality& q = ds.view().quality;
       q = q == viewer::Quality::Adaptive ? viewer::Quality::Full : viewer::Quality::Adaptive;
     }},
    {'t', false, nextTechnique},
    {'v', true, [](DesktopApp& ds) { viewPickedRegion(*ds.session, ds); }},
    {'g', true,
     [](DesktopApp& ds) {
       ds.exploration().mode() == session::ExploreMode::Grid ? showOverview(*ds.session, ds)
                                                             : enterGrid(*ds.session, ds);
     }},
    {'o', true, [](DesktopApp& ds) { showOverview(*ds.session, ds); }},
    {'l', true, [](DesktopApp& ds) { ds.explore.fourUp = !ds.explore.fourUp; }},
    {'c', true, [](DesktopApp& ds) { ds.explore.sliceColour = !ds.explore.sliceColour; }},
    {'[', true,
     [](DesktopApp& ds) {
       ds.exploration().explorer().setRegionSide(ds.exploration().explorer().regionSide() - 16);
     }},
    {']', true,
     [](DesktopApp& ds) {
       ds.exploration().explorer().setRegionSide(ds.exploration().explorer().regionSide() + 16);
     }},
};

}  // namespace

// The keys of kShortcuts but the arrows (GLFW key codes and typed
// characters, ImGui 1.86).
void handleShortcuts(DesktopApp& ds) {
  ImGuiIO& io = ImGui::GetIO();
  if (ImGui::IsKeyPressed(GLFW_KEY_F1, false)) ds.showHelp = !ds.showHelp;
  if (ImGui::IsKeyPressed(GLFW_KEY_ESCAPE, false)) ds.showHelp = false;
  if (io.WantTextInput) return;
  if (io.KeyCtrl) {
    for (int n = 0; n < 9; ++n) {
      if (ImGui::IsKeyPressed(GLFW_KEY_1 + n, false) &&
          n < static_cast<int>(ds.files.recent.entries().size())) {
        ds.openFile(ds.files.recent.entries()[static_cast<std::size_t>(n)]);
        return;
      }
    }
  }
  for (const ImWchar c : io.InputQueueCharacters) {
    for (const LetterKey& k : kLetterKeys) {
      if (lowerAscii(c) == k.letter && (!k.exploring || ds.exploring())) k.act(ds);
    }
  }
}

void drawHelpOverlay(DesktopApp& ds, float x0, float x1, float height) {
  if (!ds.showHelp) return;
  ImGui::SetNextWindowPos(ImVec2(0.5f * (x0 + x1), 0.5f * height), ImGuiCond_Always,
                          ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowBgAlpha(0.92f);
  if (ImGui::Begin("Keyboard shortcuts", &ds.showHelp,
                   ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoCollapse |
                       ImGuiWindowFlags_NoSavedSettings)) {
    if (ImGui::BeginTable("shortcuts", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV)) {
      for (const Shortcut& s : kShortcuts) {
        ImGui::TableNextRow();
        ImGui::TableSetColumnIndex(0);
        ImGui::TextUnformatted(s.keys);
        ImGui::TableSetColumnIndex(1);
        ImGui::TextUnformatted(s.action);
      }
      ImGui::EndTable();
    }
    if (!ds.files.recent.path().empty()) {
      ImGui::TextDisabled("recent volumes: %s", ds.files.recent.path().string().c_str());
    }
  }
  ImGui::End();
}

// The 3D view: mouse drags orbit (right button or shift: pan), wheel zooms;
// a left drag that starts on a crop box handle moves that face instead.
void handleViewInput(DesktopApp& ds, const Rect& view, double scale) {
  viewer::Viewer& v = ds.view();
  ImGuiIO& io = ImGui::GetIO();
  const glm::dvec2 pos((io.MousePos.x - view.p0.x) * scale, (io.MousePos.y - view.p0.y) * scale);
  const int viewW = std::max(1, static_cast<int>(std::lround((view.p1.x - view.p0.x) * scale)));
  const int viewH = std::max(1, static_cast<int>(std::lround((view.p1.y - view.p0.y) * scale)));
  Clipping& clipping = v.settings().clipping;
  if (ds.crop.dragging()) {
    ds.crop.move(pos, clipping);
    if (ImGui::IsMouseReleased(0)) ds.crop.end();
    return;
  }
  if (!io.WantCaptureMouse && view.contains(io.MousePos)) {
    if (ds.style.showCropBox && v.hasVolume() && ImGui::IsMouseClicked(0) && !io.KeyShift) {
      const glm::dvec3 extent = v.volume().extent();
      if (const auto face =
              viewer::CropHandles::hit(v.camera(), clipping, extent, pos, viewW, viewH)) {
        ds.crop.begin(v.camera(), clipping, extent, *face, pos, viewW, viewH);
        return;
      }
    }
    for (int b = 0; b < 2; ++b) {
      if (ImGui::IsMouseClicked(b)) {
        v.controller().pointerDown(
            b, pos,
            b == 1 || io.KeyShift ? viewer::PointerAction::Pan : viewer::PointerAction::Orbit);
      }
    }
    if (io.MouseWheel != 0.0f) v.controller().wheel(-io.MouseWheel);
  }
  for (int b = 0; b < 2; ++b) {
    v.controller().pointerMove(b, pos);
    if (ImGui::IsMouseReleased(b)) v.controller().pointerUp(b);
  }
}

// Mouse input on the slice views: left click/drag moves the crosshair, right
// drag picks a region, the wheel flips slices.
void handleSliceInput(DesktopApp& ds, const Tiles& tiles) {
  if (!ds.exploring() || !ds.explore.fourUp) return;
  ImGuiIO& io = ImGui::GetIO();
  const glm::dvec2 m(io.MousePos.x, io.MousePos.y);
  if (!io.WantCaptureMouse) {
    for (int t = 0; t < 3; ++t) {
      if (!tiles.slice[t].contains(io.MousePos) || !ds.slices[t].geometry) continue;
      if (ImGui::IsMouseClicked(0) || ImGui::IsMouseClicked(1)) {
        ds.dragTile = t;
        ds.dragRegion = ImGui::IsMouseClicked(1);
        ds.dragStart = m;
      }
      if (io.MouseWheel != 0.0f) stepSlice(ds, ds.slices[t], io.MouseWheel > 0.0f ? 1 : -1);
    }
  }
  if (ds.dragTile < 0) return;
  DesktopApp::SliceTile& tile = ds.slices[ds.dragTile];
  if (!ds.dragRegion && ImGui::IsMouseDown(0)) {
    const int index = ds.exploration().explorer().crosshair()[tile.geometry->axis()];
    ds.exploration().explorer().setCrosshair(
        tile.geometry->voxelAt(tile.viewport.pixelAt(m), index));
  }
  if (ds.dragRegion) {
    const ImVec2 a(static_cast<float>(ds.dragStart.x), static_cast<float>(ds.dragStart.y));
    ImGui::GetForegroundDrawList()->AddRect(a, io.MousePos, IM_COL32(255, 80, 60, 255));
    if (ImGui::IsMouseReleased(1)) {
      pickRegion(ds, tile, ds.dragStart, m);
      ds.dragTile = -1;
    }
  } else if (ImGui::IsMouseReleased(0)) {
    ds.dragTile = -1;
  }
}

// The arrow keys: grid moves in the grid view, else slices (kShortcuts).
void handleArrowKeys(DesktopApp& ds, const Tiles& tiles) {
  ImGuiIO& io = ImGui::GetIO();
  if (io.WantTextInput || !ds.exploring()) return;
  auto pressed = [](int key) { return ImGui::IsKeyPressed(key, true); };
  if (ds.exploration().mode() == session::ExploreMode::Grid) {
    if (pressed(GLFW_KEY_UP)) gridMove(*ds.session, ds, lod::ViewMove::Forward);
    if (pressed(GLFW_KEY_DOWN)) gridMove(*ds.session, ds, lod::ViewMove::Back);
    if (pressed(GLFW_KEY_LEFT)) gridMove(*ds.session, ds, lod::ViewMove::Left);
    if (pressed(GLFW_KEY_RIGHT)) gridMove(*ds.session, ds, lod::ViewMove::Right);
    if (pressed(GLFW_KEY_PAGE_UP)) gridMove(*ds.session, ds, lod::ViewMove::Up);
    if (pressed(GLFW_KEY_PAGE_DOWN)) gridMove(*ds.session, ds, lod::ViewMove::Down);
  } else {
    if (pressed(GLFW_KEY_UP)) stepSlice(ds, tileUnderPointer(ds, tiles), 1);
    if (pressed(GLFW_KEY_DOWN)) stepSlice(ds, tileUnderPointer(ds, tiles), -1);
  }
}

}  // namespace tessera::desktop
