// The 3D view right of the panel: rendered only when what it shows changed
// (on ES 3 the last frame is kept in a framebuffer and blitted, and a
// full-quality frame refines strip by strip), every frame on ES 2; or a
// store's channels, session::ChannelView's frame.
#include <cstdint>
#include <cstdio>
#include <sstream>
#include <string>

#include "DesktopApp.h"
#include "tessera/gpu/Draw.h"

namespace tessera::desktop {

namespace {

// What the volume view shows; a frame is rendered only when it changes.
// (The overlay lines too: the crosshair and region move with the slices.)
std::string viewKey(viewer::Viewer& v, int viewW, int viewH) {
  const Camera& c = v.camera();
  std::ostringstream key;
  key.precision(17);
  key << v.volumeName() << '#' << v.volumeRevision() << '|' << c.azimuthDeg << '|' << c.elevationDeg
      << '|' << c.zoom << '|' << c.target.x << c.target.y << c.target.z << '|'
      << v.tfEditor().revision() << '|' << static_cast<int>(v.settings().mode) << '|'
      << v.settings().stepVoxels << '|' << v.settings().sampling.preintegrate
      << v.settings().sampling.preintegrateLitOnly << v.settings().sampling.adaptive << '|'
      << v.settings().opacityScale << '|' << v.window().min << v.window().max << '|'
      << v.technique() << static_cast<int>(v.quality) << v.controller().interacting() << '|'
      << v.showBoundingBox << v.showAxes << '|' << v.settings().nearest << '|' << viewW << 'x'
      << viewH;
  for (const render::OverlayLine& l : v.extraLines) {
    key << "|l" << l.a.x << ',' << l.a.y << ',' << l.a.z << ',' << l.b.x << ',' << l.b.y << ','
        << l.b.z;
  }
  const RenderSettings fs = v.frameSettings();
  for (const ClipPlane& p : fs.clipping.planes) {
    key << "|p" << p.normal.x << ',' << p.normal.y << ',' << p.normal.z << ',' << p.distance;
  }
  key << "|c" << fs.clipping.cropMin.x << fs.clipping.cropMin.y << fs.clipping.cropMin.z << ','
      << fs.clipping.cropMax.x << fs.clipping.cropMax.y << fs.clipping.cropMax.z;
  const Shading& sh = v.settings().shading;
  key << '|' << sh.enabled << sh.headlight << sh.lightDirection.x << ',' << sh.lightDirection.y
      << ',' << sh.lightDirection.z << '|' << sh.ambient << ',' << sh.diffuse << ',' << sh.specular
      << ',' << sh.shininess << '|' << sh.gradientOpacity << sh.gradientLow << ','
      << sh.gradientHigh;
  return key.str();
}

// Sizes the ES 3 frame cache to the view (at a new size nothing is cached).
void fitCache(DesktopApp& ds, int viewW, int viewH) {
  if (ds.cache.width() == viewW && ds.cache.height() == viewH) return;
  ds.cache = gpu::Framebuffer();
  ds.cache = gpu::Framebuffer::create(ds.context().ledger(), "view cache", viewW, viewH);
  ds.cacheKey.clear();
}

void blitCache(DesktopApp& ds, glm::ivec2 origin, int viewW, int viewH) {
  gpu::blitFramebuffer(ds.cache.id(), {0, 0, viewW, viewH}, 0, {origin.x, origin.y, viewW, viewH});
}

// The 3D view while the zoom decides what it shows: every frame on ES 2,
// on ES 3 when the view changed, a fade runs or the zoom asks for another
// stage (the cached frame blitted otherwise). The session's mode follows
// the stage shown (the native stage is the grid view's block).
void drawZoomSwapView(DesktopApp& ds, glm::ivec2 origin, int viewW, int viewH) {
  viewer::Viewer& v = ds.view();
  session::Exploration& e = ds.exploration();
  const viewer::ZoomSwap& zs = *e.zoom();
  const double now = 1000.0 * ds.window->seconds();
  const double dtMs = ds.lastFrameMs > 0.0 ? now - ds.lastFrameMs : 0.0;
  ds.lastFrameMs = now;
  if (ds.es3) {
    fitCache(ds, viewW, viewH);
    const int shown = zs.shownStage();
    const bool swapAsked =
        shown < 0 || zs.policy().stageFor(shown, zs.overviewZoom(v.camera())) != shown;
    if (swapAsked || zs.fading() || viewKey(v, viewW, viewH) != ds.cacheKey) {
      e.zoomFrame(v, dtMs, viewW, viewH, ds.cache.id());
      ds.cacheKey = viewKey(v, viewW, viewH);
    } else if (v.refining()) {
      v.refine();  // a strip of the full-quality frame per window frame (no fade runs)
    }
    blitCache(ds, origin, viewW, viewH);
  } else {
    e.zoomFrame(v, dtMs, viewW, viewH, 0, origin);
  }
}

}  // namespace

// Patient-direction letters at the middle of each edge of a view
// rectangle (window units), so sides can be checked at a glance.
void drawEdgeLetters(const std::string& left, const std::string& right, const std::string& top,
                     const std::string& bottom, ImVec2 p0, ImVec2 p1) {
  if (left.empty()) return;
  ImDrawList* draw = ImGui::GetForegroundDrawList();
  const float pad = 8.0f;
  const ImU32 colour = IM_COL32(255, 230, 120, 255);
  auto put = [&](const std::string& text, float x, float y, float alignX, float alignY) {
    const ImVec2 size = ImGui::CalcTextSize(text.c_str());
    const ImVec2 at(x - alignX * size.x, y - alignY * size.y);
    draw->AddText(ImVec2(at.x + 1, at.y + 1), IM_COL32(0, 0, 0, 255), text.c_str());
    draw->AddText(at, colour, text.c_str());
  };
  const float cx = 0.5f * (p0.x + p1.x), cy = 0.5f * (p0.y + p1.y);
  put(left, p0.x + pad, cy, 0.0f, 0.5f);
  put(right, p1.x - pad, cy, 1.0f, 0.5f);
  put(top, cx, p0.y + pad, 0.5f, 0.0f);
  put(bottom, cx, p1.y - pad, 0.5f, 1.0f);
}

// The volume right of the panel: re-rendered only when something it shows
// changed (ES 3 blits the cached frame), every frame on ES 2 (no blit).
void drawVolumeView(DesktopApp& ds, glm::ivec2 origin, int viewW, int viewH) {
  viewer::Viewer& v = ds.view();
  const bool zooming = ds.exploring() && ds.exploration().zoom();
  try {
    if (zooming) {
      drawZoomSwapView(ds, origin, viewW, viewH);
    } else if (ds.es3) {
      fitCache(ds, viewW, viewH);
      const std::string key = viewKey(v, viewW, viewH);
      if (key != ds.cacheKey) {
        v.render(viewW, viewH, ds.cache.id());
        ds.cacheKey = key;
      } else if (v.refining()) {
        v.refine();  // a strip of the full-quality frame per window frame
      }
      blitCache(ds, origin, viewW, viewH);
    } else {
      v.render(viewW, viewH, 0, origin);
    }
  } catch (const Error& e) {
    ds.error = e.what();
    if (zooming) {
      // A stage that cannot be read or uploaded: the exploration ended the
      // swap (instead of trying again every frame); the last volume stays.
      ds.explore.zoomSwitchesGrid = false;
      ds.error += " (zoom swap turned off)";
    }
  }
  const viewer::FrameStats& fs = v.lastFrame();
  char line[160];
  std::snprintf(line, sizeof line, "%s %.0f ms at %dx%d (%s)\n%s",
                v.refining() ? "refining, strip" : "frame", fs.ms, fs.renderWidth, fs.renderHeight,
                ds.context().caps().renderer.c_str(), ds.context().caps().version.c_str());
  ds.status = line;
}

bool drawChannelView(DesktopApp& ds, const Rect& rect, int viewW, int viewH) {
  // Channels over bricks: drawStreamedFrames draws (and records) them.
  if (!channelsShown(ds) || ds.session->channelView().overBricks()) return false;
  try {
    const gpu::Texture& frame = ds.session->channelView().render(viewW, viewH);
    // Row 0 of the frame is its bottom row: ImGui's v runs down.
    ImGui::GetBackgroundDrawList()->AddImage(
        reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(frame.id())), rect.p0, rect.p1,
        ImVec2(0.0f, 1.0f), ImVec2(1.0f, 0.0f));
  } catch (const Error& e) {
    ds.error = e.what();
    return false;
  }
  char line[160];
  std::snprintf(line, sizeof line, "%d channels of %s (%s)",
                ds.session->channelView().channels().size(),
                ds.session->channelView().name().c_str(), ds.context().caps().renderer.c_str());
  ds.status = line;
  return true;
}

}  // namespace tessera::desktop
