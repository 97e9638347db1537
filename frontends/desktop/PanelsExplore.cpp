// The exploring panel: the exploring modes (overview, the picked region,
// the grid view and its moves), the crosshair's reading, the region's size
// and the zoom stages. Each step is session::Exploration's, shown in the
// session's view; the window follows through PanelHost::viewChanged.
// tests/desktop/PanelsExploreTest.cpp clicks these widgets without a window.
#include <cstdio>
#include <string>
#include <vector>

#include "Panels.h"
#include "tessera/lod/ZoomLevelPolicy.h"
#include "tessera/viewer/ZoomSwap.h"

namespace tessera::desktop {

namespace {

// Shows a step of the exploration; its error goes to the panel.
void showStep(session::Session& s, PanelHost& host, const session::ExploreStep& step) {
  reportErrors(host, [&] { s.exploration().show(s.view(), step); });
  host.viewChanged();
}

// The grid view's moves as buttons (touch-style controls beside the keys),
// named in view terms and grid terms; a move off the grid is greyed out.
void gridMoveButtons(session::Session& s, PanelHost& host) {
  const lod::GridNavigator& grid = s.exploration().explorer().grid();
  const lod::ViewMove moves[6] = {lod::ViewMove::Forward, lod::ViewMove::Back, lod::ViewMove::Left,
                                  lod::ViewMove::Right,   lod::ViewMove::Up,   lod::ViewMove::Down};
  for (int i = 0; i < 6; ++i) {
    const lod::GridMove m = lod::viewMoveToGridMove(s.view().camera().basis(), moves[i]);
    const std::string label = std::string(lod::viewMoveName(moves[i])) + " " + m.name();
    ImGui::BeginDisabled(!grid.check(grid.point(), m).moved);
    if (ImGui::Button(label.c_str(), ImVec2(110.0f, 0.0f))) gridMove(s, host, moves[i]);
    ImGui::EndDisabled();
    if (i % 3 != 2) ImGui::SameLine();
  }
}

std::string stagesText(const std::vector<lod::ZoomStage>& stages) {
  std::string text;
  for (const lod::ZoomStage& st : stages) {
    char t[80];
    std::snprintf(t, sizeof t, "%s%s L%d from zoom %.2f", text.empty() ? "" : "; ", st.name.c_str(),
                  st.level, st.enterZoom);
    text += t;
  }
  return text;
}

// The zoom policy's stages for this volume and view (lod/ZoomLevelPolicy.h,
// viewer/ZoomSwap.h), and the switch that lets the zoom alone swap the
// overview for a coarser level or the grid view and back.
void panelZoomStages(session::Session& s, ExploreUi& ui, PanelHost& host) {
  session::Exploration& e = s.exploration();
  const std::vector<lod::ZoomStage> stages =
      viewer::zoomStagesFor(e.explorer(), e.overviewLevel(), ui.viewPixels);
  const std::string text = stagesText(stages);
  ImGui::TextWrapped("zoom stages: %s", text.c_str());
  if (ImGui::Checkbox("zoom swaps levels and the grid view", &ui.zoomSwitchesGrid) &&
      !ui.zoomSwitchesGrid && e.zoom()) {
    showOverview(s, host, Follow::Keep);
  }
  // The exploration's zoom swap follows the switch (made again for new
  // stages: another volume or view size; the text names them).
  reportFailure(host, [&] { e.keepZoom(*s.device().context, ui.zoomSwitchesGrid, stages, text); });
  if (const viewer::ZoomSwap* zoom = e.zoom()) {
    ImGui::Text("zoom %.2f: %s%s", zoom->overviewZoom(s.view().camera()),
                s.view().volumeName().c_str(), zoom->fading() ? " (fading)" : "");
  }
}

}  // namespace

void showOverview(session::Session& s, PanelHost& host, Follow follow) {
  if (!s.exploring()) return;
  reportErrors(host, [&] { s.exploration().showOverview(s.view(), follow); });
  host.viewChanged();
}

void viewPickedRegion(session::Session& s, PanelHost& host) {
  if (s.exploring()) showStep(s, host, s.exploration().pickedRegion(Follow::Fill));
}

void enterGrid(session::Session& s, PanelHost& host) {
  if (s.exploring())
    showStep(s, host, s.exploration().enterGrid(s.exploration().explorer().crosshair()));
}

void gridMove(session::Session& s, PanelHost& host, lod::ViewMove move) {
  if (!s.exploring()) return;
  if (const auto step = s.exploration().move(move, s.view().camera().basis()))
    showStep(s, host, *step);
}

// The exploring controls: mode, crosshair, region size, the grid view's
// moves and the zoom stages.
void panelExplore(session::Session& s, ExploreUi& ui, PanelHost& host) {
  if (!s.exploring()) return;
  section("Explore at native resolution");
  session::Exploration& e = s.exploration();
  viewer::Explorer& ex = e.explorer();
  const glm::ivec3 d = ex.dims(), c = ex.crosshair();
  ImGui::Text("native %dx%dx%d; overview level %d of %d", d.x, d.y, d.z, e.overviewLevel(),
              ex.source().levelCount() - 1);
  const glm::dvec4 w = ex.source().shape().indexToWorld() * glm::dvec4(glm::dvec3(c), 1.0);
  ImGui::Text("crosshair (%d, %d, %d), RAS (%.0f, %.0f, %.0f) mm", c.x, c.y, c.z, w.x, w.y, w.z);
  if (s.overlay()) {
    const session::ProbeResult p = s.probe(glm::dvec3(w));
    ImGui::Text("value %g; overlay %s", p.anatomyValue, session::probeOverlayText(p).c_str());
  }
  int side = ex.regionSide();
  if (ImGui::SliderInt("region side", &side, 16, ex.maxRegionSide())) ex.setRegionSide(side);
  if (const auto& b = e.picked()) ImGui::Text("region %s", session::boxText(*b).c_str());
  if (ImGui::Button("View region (V)")) viewPickedRegion(s, host);
  ImGui::SameLine();
  if (ImGui::Button("Grid view (G)")) enterGrid(s, host);
  ImGui::SameLine();
  if (ImGui::Button("Overview (O)")) showOverview(s, host);
  if (e.mode() == session::ExploreMode::Grid) gridMoveButtons(s, host);
  if (!e.note().empty()) ImGui::TextWrapped("%s", e.note().c_str());
  ImGui::Checkbox("four views (L)", &ui.fourUp);
  ImGui::SameLine();
  ImGui::Checkbox("slices in TF colour (C)", &ui.sliceColour);
  panelZoomStages(s, ui, host);
}

}  // namespace tessera::desktop
