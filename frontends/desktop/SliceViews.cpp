// The slice views: the three slices through the crosshair at native
// resolution (with the picked region and the grid block), each read into a
// texture of the window's context when it changed, with the overlay mixed in
// (session::fuseSliceImage).
#include <cstdint>
#include <cstdio>
#include <sstream>
#include <string>

#include "DesktopApp.h"
#include "tessera/core/Image.h"

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
  const TransferFunction* colours = v.sliceColours(ds.explore.sliceColour);
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

}  // namespace tessera::desktop
