// The exploring views and panel: the three slice views through the
// crosshair (with the picked region and the grid block), and the panel of
// the exploring modes, the grid view's moves and the zoom stages. What they
// change goes through Exploring.cpp.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "DesktopApp.h"
#include "tessera/core/Image.h"
#include "tessera/lod/ZoomLevelPolicy.h"

namespace tessera::desktop {

namespace {

// The slice through the crosshair as a texture, re-read only when the
// slice, the window or its colours changed. False (the panel says why)
// when it cannot be read.
bool refreshSliceTexture(DesktopApp& ds, DesktopApp::SliceTile& tile) {
  const viewer::Explorer& ex = ds.exploration().explorer();
  if (!tile.geometry) {
    const Volume& shape = ex.source().shape();
    tile.geometry = std::make_unique<viewer::SliceGeometry>(
        ex.dims(), glm::dvec3(ex.source().levelInfo(0).spacing), shape.direction(),
        viewer::axisForPlane(shape.direction(), tile.plane));
  }
  const viewer::SliceGeometry& g = *tile.geometry;
  const int index = ex.crosshair()[g.axis()];
  viewer::Viewer& v = ds.view();
  const ValueRange w = v.window();
  std::ostringstream key;
  key.precision(17);
  const TransferFunction* colours = v.sliceColours(ds.sliceColour);
  const session::Overlay* overlay = ds.session->overlay();
  key << index << '|' << w.min << '|' << w.max << '|' << (colours != nullptr) << '|'
      << (colours ? v.tfEditor().revision() : 0) << '|'
      << static_cast<const void*>(overlay ? overlay->fused.get() : nullptr);
  if (key.str() == tile.key) return true;
  try {
    Image img = g.render(ex.source(), 0, index, w, colours);
    if (overlay) session::fuseSliceImage(img, ex.source().shape(), g.frame(), index, *overlay);
    tile.texture = gpu::Texture();
    tile.texture =
        gpu::Texture::create2D(ds.context().ledger(), "slice view",
                               gpu::rgba8For(ds.es3 ? gpu::ApiLevel::Gles3 : gpu::ApiLevel::Gles2),
                               img.width(), img.height(), img.rgba().data());
    tile.texture.setFilter(gpu::Filter::Nearest);  // voxels as they are
    tile.key = key.str();
    return true;
  } catch (const Error& e) {
    ds.error = e.what();
    return false;
  }
}

// The grid view's moves as buttons (touch-style controls beside the keys),
// named in view terms and grid terms; a move off the grid is greyed out.
void gridMoveButtons(DesktopApp& ds) {
  const lod::GridNavigator& grid = ds.exploration().explorer().grid();
  const lod::ViewMove moves[6] = {lod::ViewMove::Forward, lod::ViewMove::Back, lod::ViewMove::Left,
                                  lod::ViewMove::Right,   lod::ViewMove::Up,   lod::ViewMove::Down};
  for (int i = 0; i < 6; ++i) {
    const lod::GridMove m = lod::viewMoveToGridMove(ds.view().camera().basis(), moves[i]);
    const std::string label = std::string(lod::viewMoveName(moves[i])) + " " + m.name();
    ImGui::BeginDisabled(!grid.check(grid.point(), m).moved);
    if (ImGui::Button(label.c_str(), ImVec2(110.0f, 0.0f))) gridMove(ds, moves[i]);
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
void panelZoomStages(DesktopApp& ds) {
  const std::vector<lod::ZoomStage> stages = viewer::zoomStagesFor(
      ds.exploration().explorer(), ds.exploration().overviewLevel(), ds.viewPixels);
  const std::string text = stagesText(stages);
  ImGui::TextWrapped("zoom stages: %s", text.c_str());
  if (ImGui::Checkbox("zoom swaps levels and the grid view", &ds.zoomSwitchesGrid) &&
      !ds.zoomSwitchesGrid && ds.exploration().zoom()) {
    showOverview(ds, Follow::Keep);
  }
  keepZoomSwap(ds, stages, text);
  if (const viewer::ZoomSwap* zoom = ds.exploration().zoom()) {
    ImGui::Text("zoom %.2f: %s%s", zoom->overviewZoom(ds.view().camera()),
                ds.view().volumeName().c_str(), zoom->fading() ? " (fading)" : "");
  }
}

}  // namespace

// One slice view: the slice through the crosshair at native resolution
// (re-read only when it changed), the crosshair, the picked region, the
// patient letters and the plane's name and index.
void drawSliceTile(DesktopApp& ds, DesktopApp::SliceTile& tile, const Rect& r) {
  ImDrawList* dl = ImGui::GetBackgroundDrawList();
  dl->AddRectFilled(r.p0, r.p1, IM_COL32(0, 0, 0, 255));
  dl->AddRect(r.p0, r.p1, IM_COL32(60, 60, 60, 255));
  if (!ds.exploring() || !refreshSliceTexture(ds, tile)) return;
  const viewer::Explorer& ex = ds.exploration().explorer();
  const lod::MultiresSource& src = ex.source();
  const viewer::SliceGeometry& g = *tile.geometry;
  const int index = ex.crosshair()[g.axis()];
  const float margin = 22.0f;
  tile.viewport = viewer::SliceViewport::fit(
      g.imageSize(), {r.p0.x + margin, r.p0.y + margin},
      {std::max(1.0f, r.p1.x - r.p0.x - 2 * margin), std::max(1.0f, r.p1.y - r.p0.y - 2 * margin)});
  const viewer::SliceViewport& vp = tile.viewport;
  auto screen = [&](glm::dvec2 image) {
    const glm::dvec2 p = vp.toScreen(image);
    return ImVec2(static_cast<float>(p.x), static_cast<float>(p.y));
  };
  dl->AddImage(reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(tile.texture.id())),
               screen({0.0, 0.0}), screen(glm::dvec2(g.imageSize())));
  // The picked region (red) and the last grid block (cyan) where this slice
  // cuts them.
  const SliceFrame& f = g.frame();
  const glm::dvec2 voxelPx(src.levelInfo(0).spacing[f.colAxis] / g.pixelMm(),
                           src.levelInfo(0).spacing[f.rowAxis] / g.pixelMm());
  auto drawBox = [&](const lod::VoxelBox& box, ImU32 fill, ImU32 line) {
    if (index < box.begin[g.axis()] || index >= box.end[g.axis()]) return;
    glm::ivec3 lo = box.begin, hi = box.end - 1;
    lo[g.axis()] = hi[g.axis()] = index;
    const glm::dvec2 a = g.pointOf(lo), b = g.pointOf(hi);
    const glm::dvec2 p0 = glm::min(a, b) - 0.5 * voxelPx, p1 = glm::max(a, b) + 0.5 * voxelPx;
    if (fill) dl->AddRectFilled(screen(p0), screen(p1), fill);
    dl->AddRect(screen(p0), screen(p1), line, 0.0f, 0, 2.0f);
  };
  if (const auto& b = ds.exploration().gridBlock()) drawBox(*b, 0, IM_COL32(60, 220, 240, 255));
  if (const auto& b = ds.exploration().picked())
    drawBox(*b, IM_COL32(255, 60, 40, 50), IM_COL32(255, 70, 50, 255));
  // The crosshair through the centre of its voxel.
  const glm::dvec2 c = g.pointOf(ex.crosshair());
  const ImU32 cross = IM_COL32(255, 215, 50, 200);
  dl->AddLine(screen({c.x, 0.0}), screen({c.x, static_cast<double>(g.imageSize().y)}), cross);
  dl->AddLine(screen({0.0, c.y}), screen({static_cast<double>(g.imageSize().x), c.y}), cross);
  const char* axisName = "xyz";
  char title[96];
  std::snprintf(title, sizeof title, "%s  %c = %d / %d", f.plane.c_str(), axisName[g.axis()], index,
                g.dims()[g.axis()] - 1);
  dl->AddText(ImVec2(r.p0.x + 6, r.p0.y + 4), IM_COL32(200, 200, 200, 255), title);
  drawEdgeLetters(f.left, f.right, f.top, f.bottom, screen({0.0, 0.0}),
                  screen(glm::dvec2(g.imageSize())));
}

// The exploring controls: mode, crosshair, region size, the grid view's
// moves and the zoom stages.
void panelExplore(DesktopApp& ds) {
  if (!ds.exploring()) return;
  section("Explore at native resolution");
  viewer::Explorer& ex = ds.exploration().explorer();
  const glm::ivec3 d = ex.dims(), c = ex.crosshair();
  ImGui::Text("native %dx%dx%d; overview level %d of %d", d.x, d.y, d.z,
              ds.exploration().overviewLevel(), ex.source().levelCount() - 1);
  const glm::dvec4 w = ex.source().shape().indexToWorld() * glm::dvec4(glm::dvec3(c), 1.0);
  ImGui::Text("crosshair (%d, %d, %d), RAS (%.0f, %.0f, %.0f) mm", c.x, c.y, c.z, w.x, w.y, w.z);
  if (ds.session->overlay()) {
    const session::ProbeResult p = ds.session->probe(glm::dvec3(w));
    ImGui::Text("value %g; overlay %s", p.anatomyValue, session::probeOverlayText(p).c_str());
  }
  int side = ex.regionSide();
  if (ImGui::SliderInt("region side", &side, 16, ex.maxRegionSide())) ex.setRegionSide(side);
  if (const auto& b = ds.exploration().picked())
    ImGui::Text("region %s", session::boxText(*b).c_str());
  if (ImGui::Button("View region (V)")) viewPickedRegion(ds);
  ImGui::SameLine();
  if (ImGui::Button("Grid view (G)")) enterGrid(ds);
  ImGui::SameLine();
  if (ImGui::Button("Overview (O)")) showOverview(ds);
  if (ds.exploration().mode() == session::ExploreMode::Grid) gridMoveButtons(ds);
  if (!ds.exploration().note().empty()) ImGui::TextWrapped("%s", ds.exploration().note().c_str());
  ImGui::Checkbox("four views (L)", &ds.fourUp);
  ImGui::SameLine();
  ImGui::Checkbox("slices in TF colour (C)", &ds.sliceColour);
  panelZoomStages(ds);
}

}  // namespace tessera::desktop
