// `tessera view [FILE]`: the desktop front end of the viewer core — a GLFW
// window with an OpenGL ES context created through EGL, Dear ImGui controls
// and the TF editor drawn over the histogram. Built when GLFW and ImGui are
// found (cmake/DesktopViewer.cmake); otherwise the command says what to install.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "app/ClippingOptions.h"
#include "app/Commands.h"
#include "app/RenderJob.h"
#include "app/ShadingOptions.h"
#include "app/VolumePyramid.h"
#include "tessera/core/Error.h"

#ifdef TESSERA_DESKTOP_VIEWER
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include "tessera/core/Image.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/Draw.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/lod/ZoomLevelPolicy.h"
#include "tessera/render/LabelTable.h"
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/viewer/CropHandles.h"
#include "tessera/viewer/Explorer.h"
#include "tessera/viewer/RecentFiles.h"
#include "tessera/viewer/SliceView.h"
#include "tessera/viewer/Viewer.h"
#include "tessera/viewer/ZoomSwap.h"
#endif

namespace tessera::app {

namespace {

struct ViewOptions {
  std::string file;
  std::string series;
  std::string tf = "mr-default";
  std::string size = "1280x800";
  std::string profile = "gles3";
  double azimuth = 0.0;
  double elevation = 0.0;
  std::string screenshot;
  int frames = 3;
  bool helpOverlay = false;
  std::string layout = "four";  // four: axial, 3D, sagittal, coronal; single: 3D only
  std::vector<int> crosshair;   // X Y Z (level-0 voxel)
  bool pick = false;            // pick the region around the crosshair
  int regionSide = 0;           // 0: 256 or what the profile allows
  double zoom = 1.0;
  bool zoomGrid = false;          // the zoom swaps coarse / medium / native block (ZoomSwap)
  std::string mode = "overview";  // overview, region, grid
  ShadingOptions shading;
  ClippingOptions clipping;
  std::string projection = "composite";  // composite, mip, minip, average (RenderMode)
  // --labels [TABLE]: a label volume, as `tessera render --labels` shows it.
  std::string labels;
  CLI::Option* labelsOption = nullptr;
  bool labelVolume() const { return labelsOption != nullptr && labelsOption->count() > 0; }
};

#ifdef TESSERA_DESKTOP_VIEWER

constexpr float kPanelWidth = 390.0f;

struct DesktopState {
  viewer::Viewer* viewer = nullptr;
  std::string pendingDrop;
  double wheel = 0.0;
};

void section(const char* title) {
  ImGui::Spacing();
  ImGui::Separator();
  ImGui::TextUnformatted(title);
}

std::string fileName(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

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

// The TF editor over the histogram (Moser & Weiskopf 2008): opacity points
// over the histogram bars, colour points on a strip below. All editing goes
// through viewer::TransferFunctionEditor, the model the web page uses too.
void transferFunctionEditor(viewer::TransferFunctionEditor& ed, bool logHistogram) {
  const float width = ImGui::GetContentRegionAvail().x;
  const ImVec2 areaSize(width, 190.0f), stripSize(width, 26.0f);
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const TransferFunction& tf = ed.transferFunction();

  const ImVec2 a0 = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton("tf-opacity", areaSize);
  const bool areaActivated = ImGui::IsItemActivated(), areaActive = ImGui::IsItemActive(),
             areaReleased = ImGui::IsItemDeactivated();
  const ImVec2 a1(a0.x + areaSize.x, a0.y + areaSize.y);
  auto toScreen = [&](double x, double y) {
    return ImVec2(a0.x + static_cast<float>(x) * areaSize.x,
                  a1.y - static_cast<float>(y) * areaSize.y);
  };
  auto color32 = [](glm::dvec3 c, float alpha = 1.0f) {
    return ImGui::ColorConvertFloat4ToU32(
        ImVec4(static_cast<float>(c.r), static_cast<float>(c.g), static_cast<float>(c.b), alpha));
  };
  dl->AddRectFilled(a0, a1, IM_COL32(13, 14, 16, 255));
  const std::vector<double> bars = ed.histogramHeights(logHistogram);
  for (std::size_t i = 0; i < bars.size(); ++i) {
    const double x0 = static_cast<double>(i) / bars.size(), x1 = (i + 1.0) / bars.size();
    dl->AddRectFilled(toScreen(x0, bars[i]), toScreen(x1, 0.0), IM_COL32(58, 63, 74, 255));
  }
  // The curve, each segment in the TF colour under it.
  std::vector<ImVec2> line;
  if (!tf.opacities.empty()) line.push_back(toScreen(0.0, tf.opacities.front().alpha));
  for (const auto& p : tf.opacities) line.push_back(toScreen(p.x, p.alpha));
  if (!tf.opacities.empty()) line.push_back(toScreen(1.0, tf.opacities.back().alpha));
  for (std::size_t i = 1; i < line.size(); ++i) {
    const double xm = ((line[i - 1].x + line[i].x) * 0.5 - a0.x) / areaSize.x;
    dl->AddQuadFilled(line[i - 1], line[i], ImVec2(line[i].x, a1.y), ImVec2(line[i - 1].x, a1.y),
                      color32(tf.color(std::clamp(xm, 0.0, 1.0)), 0.35f));
  }
  if (line.size() > 1)
    dl->AddPolyline(line.data(), static_cast<int>(line.size()), IM_COL32(240, 240, 240, 255), 0,
                    1.5f);
  const auto& sel = ed.selection();
  for (std::size_t i = 0; i < tf.opacities.size(); ++i) {
    const ImVec2 c = toScreen(tf.opacities[i].x, tf.opacities[i].alpha);
    const bool selected =
        sel.channel == viewer::TfChannel::Opacity && sel.index == static_cast<int>(i);
    dl->AddCircleFilled(c, 6.0f, color32(tf.color(tf.opacities[i].x)));
    dl->AddCircle(c, 6.0f, selected ? IM_COL32(255, 213, 74, 255) : IM_COL32_WHITE, 0,
                  selected ? 3.0f : 1.5f);
  }
  dl->AddRect(a0, a1, IM_COL32(85, 85, 85, 255));

  const ImVec2 s0 = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton("tf-color", stripSize);
  const bool stripActivated = ImGui::IsItemActivated(), stripActive = ImGui::IsItemActive(),
             stripReleased = ImGui::IsItemDeactivated();
  const int steps = static_cast<int>(stripSize.x);
  for (int i = 0; i < steps; ++i) {
    const float x = s0.x + static_cast<float>(i);
    dl->AddRectFilled(ImVec2(x, s0.y), ImVec2(x + 1.0f, s0.y + stripSize.y),
                      color32(tf.color(static_cast<double>(i) / std::max(steps - 1, 1))));
  }
  for (std::size_t i = 0; i < tf.colors.size(); ++i) {
    const float x = s0.x + static_cast<float>(tf.colors[i].x) * stripSize.x;
    const float y = s0.y + stripSize.y;
    const bool selected =
        sel.channel == viewer::TfChannel::Color && sel.index == static_cast<int>(i);
    dl->AddTriangleFilled(ImVec2(x, y - 12.0f), ImVec2(x - 7.0f, y), ImVec2(x + 7.0f, y),
                          color32(tf.colors[i].rgb));
    dl->AddTriangle(ImVec2(x, y - 12.0f), ImVec2(x - 7.0f, y), ImVec2(x + 7.0f, y),
                    selected ? IM_COL32(255, 213, 74, 255) : IM_COL32_WHITE,
                    selected ? 3.0f : 1.5f);
  }

  // Gestures in editor units (x in [0,1], y = opacity), hit radius 12 px.
  const ImVec2 m = ImGui::GetIO().MousePos;
  const glm::dvec2 u((m.x - a0.x) / areaSize.x, (a1.y - m.y) / areaSize.y);
  const glm::dvec2 radius(12.0 / areaSize.x, 12.0 / areaSize.y);
  if (areaActivated) {
    ed.pointerDown(viewer::TfChannel::Opacity, glm::clamp(u, 0.0, 1.0), radius);
  } else if (stripActivated) {
    ed.pointerDown(viewer::TfChannel::Color, glm::dvec2(std::clamp(u.x, 0.0, 1.0), 0.0), radius);
  } else if ((areaActive || stripActive) && ImGui::IsMouseDragging(ImGuiMouseButton_Left, 0.0f)) {
    ed.pointerMove(u);
  }
  if (areaReleased || stripReleased) ed.pointerUp(u);
}

// Everything a desktop session holds between frames.
struct DesktopSession {
  DesktopSession(const ViewOptions& o, bool gles3) : options(o), es3(gles3) {}
  const ViewOptions& options;
  bool es3;
  GLFWwindow* window = nullptr;
  std::unique_ptr<gpu::GlContext> context;
  std::unique_ptr<viewer::Viewer> viewer;
  DesktopState input;
  std::string error;
  std::string status;
  gpu::Framebuffer cache;  // ES 3: the last volume frame, blitted while nothing changes
  std::string cacheKey;
  char pathBuf[512] = "";
  char tfPathBuf[512] = "transfer-function.json";
  char labelPathBuf[512] = "labels.txt";
  bool logHistogram = true;
  int frame = 0;
  bool showHelp = false;
  viewer::RecentFiles recent{viewer::RecentFiles::defaultPath()};

  // Exploring at native resolution (issue 15; viewer/Explorer.h).
  enum class Mode { Overview, Region, Grid };
  Mode mode = Mode::Overview;
  std::unique_ptr<viewer::Explorer> explorer;
  std::string volumeLabel;
  int overviewLevel = 0;
  std::shared_ptr<const Volume> overview;  // what the 3D view returns to
  std::optional<lod::VoxelBox> picked;     // the bread-slice region (slice views, overview)
  std::optional<lod::VoxelBox> shown;      // the region or grid block the 3D view shows
  std::optional<lod::VoxelBox> gridBlock;  // the grid view's last block (slices, overview)
  std::string exploreNote;                 // e.g. why a grid move was refused
  bool fourUp = true;
  bool sliceColour = false;       // slices in the TF's colour instead of grey
  bool zoomSwitchesGrid = false;  // the zoom swaps coarse / medium level / native grid block
  double viewPixels = 0.0;        // the 3D view's height in pixels (the policy's view)
  // While it exists, the zoom decides what the 3D view shows (viewer/ZoomSwap.h);
  // a manual mode change (region, grid, overview) ends it.
  std::unique_ptr<viewer::ZoomSwap> zoomSwap;
  std::string zoomSwapKey;  // the stages it was made for
  double lastFrameMs = 0.0;
  // The three slice views: axial, coronal, sagittal.
  struct SliceTile {
    std::string plane;
    std::unique_ptr<viewer::SliceGeometry> geometry;
    gpu::Texture texture;
    std::string key;
    viewer::SliceViewport viewport;
  };
  SliceTile slices[3] = {
      {"axial", {}, {}, "", {}}, {"coronal", {}, {}, "", {}}, {"sagittal", {}, {}, "", {}}};
  int dragTile = -1;          // a slice view being dragged in (-1: none)
  bool dragRegion = false;    // right button: drawing a region box
  glm::dvec2 dragStart{0.0};  // window units
  // The crop box drawn with a handle on each face (viewer/CropHandles.h).
  bool showCropBox = false;
  viewer::CropHandles crop;
};

// A rectangle of the window in ImGui (window) units, top-left origin.
struct Rect {
  ImVec2 p0, p1;
  bool contains(ImVec2 p) const { return p.x >= p0.x && p.y >= p0.y && p.x < p1.x && p.y < p1.y; }
};
// Where the views go right of the panel: one 3D view, or four up (axial
// top-left, 3D top-right, sagittal bottom-left, coronal bottom-right, as
// 3D Slicer's four-up layout).
struct Tiles {
  Rect view3d;
  Rect slice[3];  // axial, coronal, sagittal (empty when not four-up)
};
Tiles layoutTiles(const DesktopSession& ds, int ww, int wh) {
  const float x0 = kPanelWidth, x1 = static_cast<float>(ww), h = static_cast<float>(wh);
  Tiles t;
  if (!ds.fourUp) {
    t.view3d = {{x0, 0.0f}, {x1, h}};
    return t;
  }
  const float xm = std::floor(0.5f * (x0 + x1)), ym = std::floor(0.5f * h);
  t.slice[0] = {{x0, 0.0f}, {xm, ym}};
  t.view3d = {{xm, 0.0f}, {x1, ym}};
  t.slice[2] = {{x0, ym}, {xm, h}};
  t.slice[1] = {{xm, ym}, {x1, h}};
  return t;
}

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

// A window with an OpenGL ES context of the profile's level, made current.
GLFWwindow* openWindow(int width, int height, bool es3) {
  glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_ES_API);
  glfwWindowHint(GLFW_CONTEXT_CREATION_API, GLFW_EGL_CONTEXT_API);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, es3 ? 3 : 2);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 0);
  GLFWwindow* window = glfwCreateWindow(width, height, "Tessera", nullptr, nullptr);
  if (!window) {
    throw GpuError(std::string("cannot open a window with an OpenGL ES ") + (es3 ? "3.0" : "2.0") +
                   " context through EGL");
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);
  return window;
}

// The lines the overview shows: the region or grid block and the crosshair.
void addExploreLines(DesktopSession& ds) {
  viewer::Viewer& v = *ds.viewer;
  v.extraLines.clear();
  if (!ds.explorer || !v.hasVolume()) return;
  const glm::vec4 red(1.0f, 0.25f, 0.2f, 1.0f), cross(1.0f, 0.85f, 0.2f, 1.0f);
  const glm::dvec3 extent = v.volume().extent();
  if (ds.mode == DesktopSession::Mode::Overview) {
    const glm::ivec3 dims = ds.explorer->dims();
    if (ds.picked) {
      const auto box = viewer::boxLines(*ds.picked, dims, extent, red);
      v.extraLines.insert(v.extraLines.end(), box.begin(), box.end());
    }
    if (ds.gridBlock) {
      const glm::vec4 cyan(0.25f, 0.85f, 0.95f, 1.0f);
      const auto box = viewer::boxLines(*ds.gridBlock, dims, extent, cyan);
      v.extraLines.insert(v.extraLines.end(), box.begin(), box.end());
    }
    const auto lines = viewer::crosshairLines(ds.explorer->crosshair(), dims, extent, cross);
    v.extraLines.insert(v.extraLines.end(), lines.begin(), lines.end());
  } else if (ds.shown) {
    // The crosshair within the native sub-volume, where it falls inside it.
    const glm::ivec3 c = ds.explorer->crosshair() - ds.shown->begin;
    if (glm::all(glm::greaterThanEqual(c, glm::ivec3(0))) &&
        glm::all(glm::lessThan(c, ds.shown->size()))) {
      v.extraLines = viewer::crosshairLines(c, ds.shown->size(), extent, cross);
    }
  }
}

// The 3D view's extra lines: exploring's, then the crop box with its handles.
void updateOverlay(DesktopSession& ds) {
  addExploreLines(ds);
  viewer::Viewer& v = *ds.viewer;
  if (ds.showCropBox && v.hasVolume()) {
    const auto lines =
        viewer::CropHandles::lines(v.settings().clipping, v.volume().extent(), ds.crop.dragging());
    v.extraLines.insert(v.extraLines.end(), lines.begin(), lines.end());
  }
}

// How the camera follows a swap of the 3D view's volume (its direction
// always stays). Keep: the same point of the patient stays at the view's
// centre at the same scale (the zoom policy's swaps change the data, not
// the view: no jump). Centre: the new volume's centre, the zoom kept (a grid
// move). Fill: the new volume's centre at zoom 1 (a key or button).
enum class Follow { Keep, Centre, Fill };

// Shows `volume` (the whole volume or `box` of it) in the 3D view.
void showIn3D(DesktopSession& ds, Volume volume, const std::string& name,
              const std::optional<lod::VoxelBox>& box, Follow follow) {
  const Camera before = ds.viewer->camera();
  const std::optional<lod::VoxelBox> from = ds.shown;
  std::optional<render::LabelTable> labels;
  if (ds.viewer->labelsOn()) labels = ds.viewer->labelTable();
  ds.viewer->setVolume(std::move(volume), name);
  if (labels) ds.viewer->setLabels(std::move(*labels));  // the same table on the region
  Camera& c = ds.viewer->camera();
  if (follow == Follow::Keep) {
    const Camera kept = viewer::cameraAcrossSwap(before, from, box, ds.explorer->dims(),
                                                 ds.explorer->source().shape().spacing());
    c.target = kept.target;
    c.zoom = kept.zoom;
  } else {
    c.zoom = follow == Follow::Fill ? 1.0 : before.zoom;
  }
  c.azimuthDeg = before.azimuthDeg;
  c.elevationDeg = before.elevationDeg;
}

std::string boxText(const lod::VoxelBox& b) {
  char t[96];
  std::snprintf(t, sizeof t, "%d:%d,%d:%d,%d:%d", b.begin.x, b.end.x, b.begin.y, b.end.y, b.begin.z,
                b.end.z);
  return t;
}

void showOverview(DesktopSession& ds, Follow follow = Follow::Fill) {
  if (!ds.overview) return;
  ds.zoomSwap.reset();  // made again from the overview (panelExplore)
  try {
    showIn3D(ds, *ds.overview,
             ds.volumeLabel +
                 (ds.overviewLevel > 0 ? " (level " + std::to_string(ds.overviewLevel) + ")" : ""),
             std::nullopt, follow);
    ds.mode = DesktopSession::Mode::Overview;
    ds.shown.reset();
    ds.exploreNote.clear();
  } catch (const Error& e) {
    ds.error = e.what();
  }
  updateOverlay(ds);
}

// Reads `box` at native resolution (one bounded read) into the 3D view.
void showNative(DesktopSession& ds, const lod::VoxelBox& box, DesktopSession::Mode mode,
                Follow follow) {
  ds.zoomSwap.reset();  // the keys decide now
  try {
    showIn3D(ds, ds.explorer->readRegion(box), ds.volumeLabel + " " + boxText(box) + " (native)",
             box, follow);
    ds.mode = mode;
    ds.shown = box;
    if (mode == DesktopSession::Mode::Grid) ds.gridBlock = box;
    ds.error.clear();
  } catch (const Error& e) {
    ds.error = e.what();
  }
  updateOverlay(ds);
}

void viewPickedRegion(DesktopSession& ds) {
  if (!ds.explorer) return;
  if (!ds.picked) ds.picked = ds.explorer->regionAt(ds.explorer->crosshair());
  showNative(ds, *ds.picked, DesktopSession::Mode::Region, Follow::Fill);
}

// The grid view starts at the grid point nearest the crosshair (the zoom
// swap, viewer/ZoomSwap.h, picks the point the view is centred on itself).
void enterGrid(DesktopSession& ds) {
  if (!ds.explorer) return;
  lod::GridNavigator& g = ds.explorer->grid();
  const glm::dvec3 voxel = glm::dvec3(ds.explorer->crosshair()) + 0.5;
  const glm::dvec3 c = voxel / glm::dvec3(g.cellSize());
  g.moveTo(glm::clamp(glm::ivec3(glm::round(c)), glm::ivec3(0), g.cells()));
  ds.exploreNote = g.describe(g.point());
  showNative(ds, g.blockBox(g.point()), DesktopSession::Mode::Grid, Follow::Fill);
}

void gridMove(DesktopSession& ds, lod::ViewMove move) {
  lod::GridNavigator& g = ds.explorer->grid();
  const lod::GridMove m = lod::viewMoveToGridMove(ds.viewer->camera().basis(), move);
  const lod::MoveResult r = g.apply(m);
  if (!r.moved) {
    ds.exploreNote = std::string(lod::viewMoveName(move)) + " = " + m.name() + ": " + r.reason;
    return;
  }
  ds.exploreNote =
      std::string(lod::viewMoveName(move)) + " = " + m.name() + "; " + g.describe(g.point());
  showNative(ds, g.blockBox(g.point()), DesktopSession::Mode::Grid, Follow::Centre);
}

// Loads a volume as a pyramid (viewer/Explorer.h reads regions and slices
// from it; a store or head:WxHxD is read box by box), shows its overview;
// an error is shown in the panel and the previous volume stays. Files and
// folders (not generated volumes) go to the recent list.
void openVolume(DesktopSession& ds, const std::string& spec) {
  try {
    const VolumePyramid pyramid = openVolumePyramid(spec, {.series = ds.options.series});
    const gpu::DeviceLimits& limits = ds.viewer->limits();
    auto explorer =
        std::make_unique<viewer::Explorer>(pyramid.source, viewer::regionBudgetBytes(limits));
    const int level = explorer->overviewLevel(viewer::overviewVoxelBudget(limits));
    auto overview = std::make_shared<const Volume>(explorer->readLevel(level));
    const std::string label = fileName(spec);
    ds.viewer->setVolume(*overview,
                         label + (level > 0 ? " (level " + std::to_string(level) + ")" : ""));
    ds.explorer = std::move(explorer);
    ds.overview = std::move(overview);
    ds.overviewLevel = level;
    ds.volumeLabel = label;
    ds.mode = DesktopSession::Mode::Overview;
    ds.picked.reset();
    ds.shown.reset();
    ds.gridBlock.reset();
    ds.exploreNote.clear();
    for (auto& tile : ds.slices) {
      tile.geometry.reset();
      tile.key.clear();
    }
    updateOverlay(ds);
    ds.error.clear();
  } catch (const Error& e) {
    ds.error = std::string(e.what()) + " (the previous volume stays)";
    std::error_code ec;
    if (!std::filesystem::exists(spec, ec)) {
      try {
        ds.recent.remove(spec);  // gone: no longer offered
      } catch (const Error&) {
      }
    }
    return;
  }
  if (spec.rfind("gen:", 0) == 0 || spec.rfind("head:", 0) == 0) return;
  try {
    std::error_code ec;
    const std::filesystem::path full = std::filesystem::absolute(spec, ec);
    ds.recent.add(ec ? spec : full.lexically_normal().string());
  } catch (const Error& e) {
    ds.error = e.what();
  }
}

// One slice view: the slice through the crosshair at native resolution
// (re-read only when it changed), the crosshair, the picked region, the
// patient letters and the plane's name and index.
void drawSliceTile(DesktopSession& ds, DesktopSession::SliceTile& tile, const Rect& r) {
  ImDrawList* dl = ImGui::GetBackgroundDrawList();
  dl->AddRectFilled(r.p0, r.p1, IM_COL32(0, 0, 0, 255));
  dl->AddRect(r.p0, r.p1, IM_COL32(60, 60, 60, 255));
  if (!ds.explorer) return;
  const viewer::Explorer& ex = *ds.explorer;
  const lod::MultiresSource& src = ex.source();
  if (!tile.geometry) {
    const Volume& shape = src.shape();
    tile.geometry = std::make_unique<viewer::SliceGeometry>(
        ex.dims(), glm::dvec3(src.levelInfo(0).spacing), shape.direction(),
        viewer::axisForPlane(shape.direction(), tile.plane));
  }
  const viewer::SliceGeometry& g = *tile.geometry;
  const int index = ex.crosshair()[g.axis()];
  viewer::Viewer& v = *ds.viewer;
  const ValueRange w = v.window();
  std::ostringstream key;
  key.precision(17);
  const TransferFunction* colours = v.sliceColours(ds.sliceColour);
  key << index << '|' << w.min << '|' << w.max << '|' << (colours != nullptr) << '|'
      << (colours ? v.tfEditor().revision() : 0);
  if (key.str() != tile.key) {
    try {
      const Image img = g.render(src, 0, index, w, colours);
      tile.texture = gpu::Texture();
      tile.texture = gpu::Texture::create2D(
          ds.context->ledger(), "slice view",
          gpu::rgba8For(ds.es3 ? gpu::ApiLevel::Gles3 : gpu::ApiLevel::Gles2), img.width(),
          img.height(), img.rgba().data());
      tile.texture.setFilter(gpu::Filter::Nearest);  // voxels as they are
      tile.key = key.str();
    } catch (const Error& e) {
      ds.error = e.what();
      return;
    }
  }
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
  if (ds.gridBlock) drawBox(*ds.gridBlock, 0, IM_COL32(60, 220, 240, 255));
  if (ds.picked) drawBox(*ds.picked, IM_COL32(255, 60, 40, 50), IM_COL32(255, 70, 50, 255));
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

// A region from a right-drag in a slice view: the dragged rectangle in the
// slice's plane (a click: the default cube around the point), the region's
// side across it, centred on the slice; clamped to the budget and volume.
void pickRegion(DesktopSession& ds, const DesktopSession::SliceTile& tile, glm::dvec2 a,
                glm::dvec2 b) {
  const viewer::SliceGeometry& g = *tile.geometry;
  const int index = ds.explorer->crosshair()[g.axis()];
  const glm::ivec2 pa = tile.viewport.pixelAt(a);
  const glm::ivec2 pb = glm::length(b - a) < 4.0 ? pa : tile.viewport.pixelAt(b);
  ds.picked = ds.explorer->regionFromSlice(g, pa, pb, index);
}

// Mouse input on the slice views: left click/drag moves the crosshair, right
// drag picks a region, the wheel flips slices.
void handleSliceInput(DesktopSession& ds, const Tiles& tiles) {
  if (!ds.explorer || !ds.fourUp) return;
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
      if (io.MouseWheel != 0.0f) {
        glm::ivec3 c = ds.explorer->crosshair();
        c[ds.slices[t].geometry->axis()] += io.MouseWheel > 0.0f ? 1 : -1;
        ds.explorer->setCrosshair(c);
      }
    }
  }
  if (ds.dragTile < 0) return;
  DesktopSession::SliceTile& tile = ds.slices[ds.dragTile];
  if (!ds.dragRegion && ImGui::IsMouseDown(0)) {
    const int index = ds.explorer->crosshair()[tile.geometry->axis()];
    ds.explorer->setCrosshair(tile.geometry->voxelAt(tile.viewport.pixelAt(m), index));
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

// The slice under the pointer (axial if none) one step up or down.
void stepSlice(DesktopSession& ds, const Tiles& tiles, int step) {
  const ImVec2 m = ImGui::GetIO().MousePos;
  int t = 0;
  for (int i = 0; i < 3; ++i) {
    if (tiles.slice[i].contains(m)) t = i;
  }
  if (!ds.slices[t].geometry) return;
  glm::ivec3 c = ds.explorer->crosshair();
  c[ds.slices[t].geometry->axis()] += step;
  ds.explorer->setCrosshair(c);
}

// The keys of the exploring modes (kShortcuts).
void handleExploreKeys(DesktopSession& ds, const Tiles& tiles) {
  ImGuiIO& io = ImGui::GetIO();
  if (io.WantTextInput || !ds.explorer) return;
  const bool grid = ds.mode == DesktopSession::Mode::Grid;
  auto pressed = [](int key) { return ImGui::IsKeyPressed(key, true); };
  if (grid) {
    if (pressed(GLFW_KEY_UP)) gridMove(ds, lod::ViewMove::Forward);
    if (pressed(GLFW_KEY_DOWN)) gridMove(ds, lod::ViewMove::Back);
    if (pressed(GLFW_KEY_LEFT)) gridMove(ds, lod::ViewMove::Left);
    if (pressed(GLFW_KEY_RIGHT)) gridMove(ds, lod::ViewMove::Right);
    if (pressed(GLFW_KEY_PAGE_UP)) gridMove(ds, lod::ViewMove::Up);
    if (pressed(GLFW_KEY_PAGE_DOWN)) gridMove(ds, lod::ViewMove::Down);
  } else {
    if (pressed(GLFW_KEY_UP)) stepSlice(ds, tiles, 1);
    if (pressed(GLFW_KEY_DOWN)) stepSlice(ds, tiles, -1);
  }
  for (const ImWchar c : io.InputQueueCharacters) {
    switch (c) {
      case 'v':
      case 'V':
        viewPickedRegion(ds);
        break;
      case 'g':
      case 'G':
        grid ? showOverview(ds) : enterGrid(ds);
        break;
      case 'o':
      case 'O':
        showOverview(ds);
        break;
      case 'l':
      case 'L':
        ds.fourUp = !ds.fourUp;
        break;
      case 'c':
      case 'C':
        ds.sliceColour = !ds.sliceColour;
        break;
      case '[':
        ds.explorer->setRegionSide(ds.explorer->regionSide() - 16);
        break;
      case ']':
        ds.explorer->setRegionSide(ds.explorer->regionSide() + 16);
        break;
      default:
        break;
    }
  }
}

void drawHelpOverlay(DesktopSession& ds, float x0, float x1, float height) {
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
    if (!ds.recent.path().empty()) {
      ImGui::TextDisabled("recent volumes: %s", ds.recent.path().string().c_str());
    }
  }
  ImGui::End();
}

void nextTechnique(DesktopSession& ds) {
  const std::vector<std::string> names = render::TechniqueRegistry::global().names();
  const auto at = std::find(names.begin(), names.end(), ds.viewer->technique());
  const std::size_t next = at == names.end() ? 0 : (at - names.begin() + 1) % names.size();
  try {
    ds.viewer->setTechnique(names[next]);
  } catch (const Error& e) {
    ds.error = e.what();
  }
}

// The keys of kShortcuts (GLFW key codes and typed characters, ImGui 1.86).
void handleShortcuts(DesktopSession& ds) {
  ImGuiIO& io = ImGui::GetIO();
  if (ImGui::IsKeyPressed(GLFW_KEY_F1, false)) ds.showHelp = !ds.showHelp;
  if (ImGui::IsKeyPressed(GLFW_KEY_ESCAPE, false)) ds.showHelp = false;
  if (io.WantTextInput) return;
  if (io.KeyCtrl) {
    for (int n = 0; n < 9; ++n) {
      if (ImGui::IsKeyPressed(GLFW_KEY_1 + n, false) &&
          n < static_cast<int>(ds.recent.entries().size())) {
        openVolume(ds, ds.recent.entries()[static_cast<std::size_t>(n)]);
        return;
      }
    }
  }
  viewer::Viewer& v = *ds.viewer;
  for (const ImWchar c : io.InputQueueCharacters) {
    switch (c) {
      case '?':
        ds.showHelp = !ds.showHelp;
        break;
      case 'r':
      case 'R':
        v.resetCamera();
        break;
      case 'b':
      case 'B':
        v.showBoundingBox = !v.showBoundingBox;
        break;
      case 'a':
      case 'A':
        v.showAxes = !v.showAxes;
        break;
      case 'm':
      case 'M':
        v.settings().mode =
            v.settings().mode == RenderMode::Mip ? RenderMode::Composite : RenderMode::Mip;
        break;
      case 'q':
      case 'Q':
        v.quality = v.quality == viewer::Quality::Adaptive ? viewer::Quality::Full
                                                           : viewer::Quality::Adaptive;
        break;
      case 't':
      case 'T':
        nextTechnique(ds);
        break;
      default:
        break;
    }
  }
}

// The 3D view: mouse drags orbit (right button or shift: pan), wheel zooms;
// a left drag that starts on a crop box handle moves that face instead.
void handleViewInput(DesktopSession& ds, const Rect& view, double scale) {
  viewer::Viewer& v = *ds.viewer;
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
    if (ds.showCropBox && v.hasVolume() && ImGui::IsMouseClicked(0) && !io.KeyShift) {
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

void panelFile(DesktopSession& ds) {
  ImGui::TextWrapped("%s", ds.viewer->description().c_str());
  ImGui::InputText("##path", ds.pathBuf, sizeof ds.pathBuf);
  ImGui::SameLine();
  if (ImGui::Button("Open") && ds.pathBuf[0]) openVolume(ds, ds.pathBuf);
  ImGui::TextDisabled("or drop a file on the window; F1: keyboard shortcuts");
  if (!ds.recent.entries().empty() && ImGui::BeginCombo("recent", "open a recent volume")) {
    std::string chosen;
    for (std::size_t i = 0; i < ds.recent.entries().size(); ++i) {
      const std::string& path = ds.recent.entries()[i];
      const std::string label = std::to_string(i + 1) + "  " + fileName(path) + "##" + path;
      if (ImGui::Selectable(label.c_str())) chosen = path;
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", path.c_str());
    }
    ImGui::EndCombo();
    if (!chosen.empty()) openVolume(ds, chosen);
  }
  if (!ds.error.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.45f, 0.4f, 1.0f));
    ImGui::TextWrapped("%s", ds.error.c_str());
    ImGui::PopStyleColor();
  }
}

void panelTransferFunction(DesktopSession& ds) {
  section("Transfer function");
  viewer::TransferFunctionEditor& ed = ds.viewer->tfEditor();
  transferFunctionEditor(ed, ds.logHistogram);
  if (ImGui::BeginCombo("preset", ed.transferFunction().name.c_str())) {
    for (const std::string& name : TransferFunction::presetNames()) {
      if (ImGui::Selectable(name.c_str())) ed.loadPreset(name);
    }
    ImGui::EndCombo();
  }
  ImGui::Checkbox("log histogram", &ds.logHistogram);
  const auto sel = ed.selection();
  ImGui::BeginDisabled(sel.index < 0);
  if (ImGui::Button("Delete point")) ed.removeSelected();
  ImGui::EndDisabled();
  if (sel.channel == viewer::TfChannel::Color && sel.index >= 0 &&
      sel.index < static_cast<int>(ed.transferFunction().colors.size())) {
    const glm::dvec3 c = ed.transferFunction().colors[static_cast<std::size_t>(sel.index)].rgb;
    float rgb[3] = {static_cast<float>(c.r), static_cast<float>(c.g), static_cast<float>(c.b)};
    ImGui::SameLine();
    if (ImGui::ColorEdit3("colour", rgb, ImGuiColorEditFlags_NoInputs)) {
      ed.setSelectedColor(glm::dvec3(rgb[0], rgb[1], rgb[2]));
    }
  }
  ImGui::InputText("##tfpath", ds.tfPathBuf, sizeof ds.tfPathBuf);
  ImGui::SameLine();
  if (ImGui::Button("Save")) {
    try {
      ed.transferFunction().save(ds.tfPathBuf);
      ds.error.clear();
    } catch (const Error& e) {
      ds.error = e.what();
    }
  }
  ImGui::SameLine();
  if (ImGui::Button("Load")) {
    try {
      ed.setTransferFunction(TransferFunction::load(ds.tfPathBuf));
      ds.error.clear();
    } catch (const Error& e) {
      ds.error = e.what();
    }
  }
}

void panelWindowLevel(viewer::Viewer& v) {
  if (!v.hasVolume()) return;
  section("Window / level");
  const ValueRange r = v.valueRange(), w = v.window();
  const double span = std::max(r.width(), 1e-12);
  float win = static_cast<float>(w.width()), level = static_cast<float>(0.5 * (w.min + w.max));
  bool changed = ImGui::SliderFloat("window", &win, static_cast<float>(span / 1000.0),
                                    static_cast<float>(span));
  changed |=
      ImGui::SliderFloat("level", &level, static_cast<float>(r.min), static_cast<float>(r.max));
  if (changed) v.setWindowLevel(win, level);
  if (ImGui::Button("Full range")) v.resetWindow();
}

void panelRendering(DesktopSession& ds) {
  viewer::Viewer& v = *ds.viewer;
  section("Rendering");
  int mode = static_cast<int>(v.settings().mode);
  if (ImGui::Combo("mode", &mode, "composite\0MIP\0MinIP\0average\0")) {
    v.settings().mode = static_cast<RenderMode>(mode);
  }
  if (ImGui::BeginCombo("technique", v.technique().c_str())) {
    for (const std::string& t : render::TechniqueRegistry::global().names()) {
      if (ImGui::Selectable(t.c_str(), t == v.technique())) {
        try {
          v.setTechnique(t);
        } catch (const Error& e) {
          ds.error = e.what();
        }
      }
    }
    ImGui::EndCombo();
  }
  int quality = v.quality == viewer::Quality::Adaptive ? 0 : 1;
  if (ImGui::Combo("quality", &quality, "adaptive\0full\0")) {
    v.quality = quality == 0 ? viewer::Quality::Adaptive : viewer::Quality::Full;
  }
  float step = static_cast<float>(v.settings().stepVoxels);
  if (ImGui::SliderFloat("step (voxels)", &step, 0.25f, 2.0f)) v.settings().stepVoxels = step;
  // `tessera render`'s fast path (docs/sampling.md): adaptive steps, on by
  // default (off: samples at exactly the step above), post-classified by
  // default; pre-integration for every frame or, as the CLI's --preintegrate
  // lit, for shaded or gradient-opacity frames only.
  Sampling& sampling = v.settings().sampling;
  int classification = !sampling.preintegrate ? 0 : sampling.preintegrateLitOnly ? 2 : 1;
  if (ImGui::Combo("classification", &classification,
                   "post-classified\0pre-integrated\0pre-integrated when lit\0")) {
    sampling.preintegrate = classification != 0;
    sampling.preintegrateLitOnly = classification == 2;
  }
  ImGui::Checkbox("adaptive steps", &sampling.adaptive);
  float opacity = static_cast<float>(v.settings().opacityScale);
  if (ImGui::SliderFloat("opacity x", &opacity, 0.0f, 4.0f)) v.settings().opacityScale = opacity;
  ImGui::Checkbox("bounding box", &v.showBoundingBox);
  ImGui::SameLine();
  ImGui::Checkbox("axes", &v.showAxes);
  if (ImGui::Button("Reset view")) v.resetCamera();
}

// The crop box (fractions of each axis; handles to drag in the 3D view) and a
// clip plane that follows the camera.
void panelClipping(DesktopSession& ds) {
  viewer::Viewer& v = *ds.viewer;
  section("Clipping");
  ImGui::Checkbox("crop box handles (drag in 3D)", &ds.showCropBox);
  Clipping& c = v.settings().clipping;
  for (int a = 0; a < 3; ++a) {
    float range[2] = {static_cast<float>(c.cropMin[a]), static_cast<float>(c.cropMax[a])};
    const std::string label = std::string("crop ") + "xyz"[a];
    if (ImGui::SliderFloat2(label.c_str(), range, 0.0f, 1.0f) && range[0] < range[1] - 0.01f) {
      c.cropMin[a] = range[0];
      c.cropMax[a] = range[1];
    }
  }
  if (c.cropped() && ImGui::Button("Reset crop")) {
    c.cropMin = glm::dvec3(0.0);
    c.cropMax = glm::dvec3(1.0);
  }
  ImGui::Checkbox("plane follows camera", &v.clipPlaneFollowsCamera);
  if (v.clipPlaneFollowsCamera) {
    const float reach = static_cast<float>(0.5 * glm::length(v.volume().extent()));
    float d = static_cast<float>(v.followingPlaneDistance);
    if (ImGui::SliderFloat("plane depth (mm)", &d, -reach, reach)) v.followingPlaneDistance = d;
  }
}

// Blinn-Phong shading (RenderSettings::shading): on/off, the light, the terms.
// Label volumes: on/off (the default palette), a table file, and every
// label with its colour and a visibility box (aal has 116: scrollable).
void panelLabels(DesktopSession& ds) {
  viewer::Viewer& v = *ds.viewer;
  section("Labels");
  bool on = v.labelsOn();
  if (ImGui::Checkbox("label volume (atlas)", &on)) {
    try {
      if (on) {
        v.setLabelsDefault();
      } else {
        v.clearLabels();
        v.tfEditor().setTransferFunction(TransferFunction::fromPresetOrFile(ds.options.tf));
      }
      ds.error.clear();
    } catch (const Error& e) {
      ds.error = e.what();
    }
  }
  ImGui::InputText("##labeltable", ds.labelPathBuf, sizeof ds.labelPathBuf);
  ImGui::SameLine();
  if (ImGui::Button("load table")) {
    try {
      v.setLabels(render::LabelTable::load(ds.labelPathBuf));
      ds.error.clear();
    } catch (const Error& e) {
      ds.error = e.what();
    }
  }
  if (!v.labelsOn()) return;
  if (ImGui::Button("show all")) v.setAllLabelsVisible(true);
  ImGui::SameLine();
  if (ImGui::Button("hide all")) v.setAllLabelsVisible(false);
  ImGui::SameLine();
  ImGui::Text("%zu labels", v.labelTable().labels.size());
  ImGui::BeginChild("labels", ImVec2(0.0f, 220.0f), true);
  std::vector<std::pair<int, bool>> changes;
  for (const auto& [value, label] : v.labelTable().labels) {
    ImGui::PushID(value);
    const ImVec4 c(static_cast<float>(label.color.r), static_cast<float>(label.color.g),
                   static_cast<float>(label.color.b), 1.0f);
    ImGui::ColorButton("##swatch", c, ImGuiColorEditFlags_NoTooltip, ImVec2(14.0f, 14.0f));
    ImGui::SameLine();
    bool visible = label.visible;
    const std::string text = std::to_string(value) + " " + label.name;
    if (ImGui::Checkbox(text.c_str(), &visible)) changes.emplace_back(value, visible);
    ImGui::PopID();
  }
  ImGui::EndChild();
  for (const auto& [value, visible] : changes) v.setLabelVisible(value, visible);
}

void panelShading(viewer::Viewer& v) {
  section("Shading");
  Shading& s = v.settings().shading;
  auto slider = [](const char* label, double& value, float lo, float hi) {
    float f = static_cast<float>(value);
    if (ImGui::SliderFloat(label, &f, lo, hi)) value = f;
  };
  ImGui::Checkbox("shade (gradient lighting)", &s.enabled);
  // Gradient-magnitude opacity modulation, with or without the light.
  ImGui::Checkbox("gradient opacity", &s.gradientOpacity);
  if (s.gradientOpacity) {
    slider("|gradient| from", s.gradientLow, 0.0f, 0.3f);
    slider("|gradient| full", s.gradientHigh, 0.001f, 0.6f);
    s.gradientHigh = std::max(s.gradientHigh, s.gradientLow + 0.001);
  }
  if (!s.enabled) return;
  ImGui::Checkbox("headlight", &s.headlight);
  if (!s.headlight) {
    float dir[3] = {static_cast<float>(s.lightDirection.x), static_cast<float>(s.lightDirection.y),
                    static_cast<float>(s.lightDirection.z)};
    if (ImGui::SliderFloat3("light (RAS)", dir, -1.0f, 1.0f) &&
        std::abs(dir[0]) + std::abs(dir[1]) + std::abs(dir[2]) > 1e-3f) {
      s.lightDirection = {dir[0], dir[1], dir[2]};
    }
  }
  slider("ambient", s.ambient, 0.0f, 1.0f);
  slider("diffuse", s.diffuse, 0.0f, 1.0f);
  slider("specular", s.specular, 0.0f, 1.0f);
  slider("shininess", s.shininess, 1.0f, 128.0f);
}

// The exploring controls (issue 15): mode, crosshair, region size, the
// grid view's moves as buttons (touch-style controls beside the keys), and
// the zoom policy's stages (lod/ZoomLevelPolicy.h), which can switch the
// overview to the grid view and back by zoom alone.
void panelExplore(DesktopSession& ds) {
  if (!ds.explorer) return;
  section("Explore at native resolution");
  viewer::Explorer& ex = *ds.explorer;
  const glm::ivec3 d = ex.dims(), c = ex.crosshair();
  ImGui::Text("native %dx%dx%d; overview level %d of %d", d.x, d.y, d.z, ds.overviewLevel,
              ex.source().levelCount() - 1);
  const glm::dvec4 w = ex.source().shape().indexToWorld() * glm::dvec4(glm::dvec3(c), 1.0);
  ImGui::Text("crosshair (%d, %d, %d), RAS (%.0f, %.0f, %.0f) mm", c.x, c.y, c.z, w.x, w.y, w.z);
  int side = ex.regionSide();
  if (ImGui::SliderInt("region side", &side, 16, ex.maxRegionSide())) ex.setRegionSide(side);
  if (ds.picked) ImGui::Text("region %s", boxText(*ds.picked).c_str());
  if (ImGui::Button("View region (V)")) viewPickedRegion(ds);
  ImGui::SameLine();
  if (ImGui::Button("Grid view (G)")) enterGrid(ds);
  ImGui::SameLine();
  if (ImGui::Button("Overview (O)")) showOverview(ds);
  if (ds.mode == DesktopSession::Mode::Grid) {
    const lod::ViewMove moves[6] = {lod::ViewMove::Forward, lod::ViewMove::Back,
                                    lod::ViewMove::Left,    lod::ViewMove::Right,
                                    lod::ViewMove::Up,      lod::ViewMove::Down};
    for (int i = 0; i < 6; ++i) {
      const lod::GridMove m = lod::viewMoveToGridMove(ds.viewer->camera().basis(), moves[i]);
      const std::string label = std::string(lod::viewMoveName(moves[i])) + " " + m.name();
      const bool legal = ex.grid().check(ex.grid().point(), m).moved;
      ImGui::BeginDisabled(!legal);
      if (ImGui::Button(label.c_str(), ImVec2(110.0f, 0.0f))) gridMove(ds, moves[i]);
      ImGui::EndDisabled();
      if (i % 3 != 2) ImGui::SameLine();
    }
  }
  if (!ds.exploreNote.empty()) ImGui::TextWrapped("%s", ds.exploreNote.c_str());
  ImGui::Checkbox("four views (L)", &ds.fourUp);
  ImGui::SameLine();
  ImGui::Checkbox("slices in TF colour (C)", &ds.sliceColour);
  // The zoom swap's stages for this volume and view (viewer/ZoomSwap.h).
  const std::vector<lod::ZoomStage> stages =
      viewer::zoomStagesFor(ex, ds.overviewLevel, ds.viewPixels);
  std::string text;
  for (const lod::ZoomStage& st : stages) {
    char t[80];
    std::snprintf(t, sizeof t, "%s%s L%d from zoom %.2f", text.empty() ? "" : "; ", st.name.c_str(),
                  st.level, st.enterZoom);
    text += t;
  }
  ImGui::TextWrapped("zoom stages: %s", text.c_str());
  if (ImGui::Checkbox("zoom swaps levels and the grid view", &ds.zoomSwitchesGrid) &&
      !ds.zoomSwitchesGrid && ds.zoomSwap) {
    showOverview(ds, Follow::Keep);
  }
  if (!ds.zoomSwitchesGrid || stages.size() < 2) {
    ds.zoomSwap.reset();
    return;
  }
  if (ds.zoomSwap) {
    ImGui::Text("zoom %.2f: %s%s", ds.zoomSwap->overviewZoom(ds.viewer->camera()),
                ds.viewer->volumeName().c_str(), ds.zoomSwap->fading() ? " (fading)" : "");
  }
  // Made from the overview (after a manual mode change: once back there);
  // new stages (another volume or view size) make it again.
  if (ds.mode != DesktopSession::Mode::Overview || (ds.zoomSwap && ds.zoomSwapKey == text)) return;
  try {
    ds.zoomSwap = std::make_unique<viewer::ZoomSwap>(*ds.context, ex, stages);
    ds.zoomSwap->keepLevel(ds.overviewLevel, ds.overview);
    ds.zoomSwap->setLabel(ds.volumeLabel);
    ds.zoomSwapKey = text;
  } catch (const Error& e) {
    ds.error = e.what();
  }
}

// The control panel at the window's left edge.
void drawPanel(DesktopSession& ds, int windowHeight) {
  ImGui::SetNextWindowPos(ImVec2(0, 0));
  ImGui::SetNextWindowSize(ImVec2(kPanelWidth, static_cast<float>(windowHeight)));
  ImGui::Begin("Tessera", nullptr,
               ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
  panelFile(ds);
  panelExplore(ds);
  const bool labelsFirst = ds.viewer->labelsOn();  // the list before the TF it drives
  if (labelsFirst) panelLabels(ds);
  panelTransferFunction(ds);
  panelWindowLevel(*ds.viewer);
  panelRendering(ds);
  panelShading(*ds.viewer);
  panelClipping(ds);
  if (!labelsFirst) panelLabels(ds);
  ImGui::Separator();
  ImGui::TextWrapped("%s", ds.status.c_str());
  ImGui::End();
}

// What the volume view shows; a frame is rendered only when it changes.
// (The overlay lines too: the crosshair and region move with the slices.)
std::string viewKey(viewer::Viewer& v, int viewW, int viewH) {
  const Camera& c = v.camera();
  std::ostringstream key;
  key.precision(17);
  key << v.volumeName() << '|' << c.azimuthDeg << '|' << c.elevationDeg << '|' << c.zoom << '|'
      << c.target.x << c.target.y << c.target.z << '|' << v.tfEditor().revision() << '|'
      << static_cast<int>(v.settings().mode) << '|' << v.settings().stepVoxels << '|'
      << v.settings().sampling.preintegrate << v.settings().sampling.preintegrateLitOnly
      << v.settings().sampling.adaptive << '|' << v.settings().opacityScale << '|' << v.window().min
      << v.window().max << '|' << v.technique() << static_cast<int>(v.quality)
      << v.controller().interacting() << '|' << v.showBoundingBox << v.showAxes << '|'
      << v.settings().nearest << '|' << viewW << 'x' << viewH;
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

// The 3D view while the zoom decides what it shows: every frame on ES 2,
// on ES 3 when the view changed, a fade runs or the zoom asks for another
// stage (the cached frame blitted otherwise). The session's mode follows
// the stage shown (the native stage is the grid view's block).
void drawZoomSwapView(DesktopSession& ds, glm::ivec2 origin, int viewW, int viewH) {
  viewer::Viewer& v = *ds.viewer;
  viewer::ZoomSwap& zs = *ds.zoomSwap;
  const double now = 1000.0 * glfwGetTime();
  const double dtMs = ds.lastFrameMs > 0.0 ? now - ds.lastFrameMs : 0.0;
  ds.lastFrameMs = now;
  if (ds.es3) {
    if (ds.cache.width() != viewW || ds.cache.height() != viewH) {
      ds.cache = gpu::Framebuffer();
      ds.cache = gpu::Framebuffer::create(ds.context->ledger(), "view cache", viewW, viewH);
      ds.cacheKey.clear();
    }
    const int shown = zs.shownStage();
    const bool swapAsked =
        shown < 0 || zs.policy().stageFor(shown, zs.overviewZoom(v.camera())) != shown;
    if (swapAsked || zs.fading() || viewKey(v, viewW, viewH) != ds.cacheKey) {
      zs.frame(v, dtMs, viewW, viewH, ds.cache.id());
      ds.cacheKey = viewKey(v, viewW, viewH);
    } else if (v.refining()) {
      v.refine();  // a strip of the full-quality frame per window frame (no fade runs)
    }
    gpu::blitFramebuffer(ds.cache.id(), {0, 0, viewW, viewH}, 0,
                         {origin.x, origin.y, viewW, viewH});
  } else {
    zs.frame(v, dtMs, viewW, viewH, 0, origin);
  }
  if (zs.shownBox()) {
    ds.mode = DesktopSession::Mode::Grid;
    ds.shown = ds.gridBlock = zs.shownBox();
  } else {
    ds.mode = DesktopSession::Mode::Overview;
    ds.shown.reset();
  }
}

// The volume right of the panel: re-rendered only when something it shows
// changed (ES 3 blits the cached frame), every frame on ES 2 (no blit).
void drawVolumeView(DesktopSession& ds, glm::ivec2 origin, int viewW, int viewH) {
  viewer::Viewer& v = *ds.viewer;
  try {
    if (ds.zoomSwap) {
      drawZoomSwapView(ds, origin, viewW, viewH);
    } else if (ds.es3) {
      const std::string key = viewKey(v, viewW, viewH);
      if (key != ds.cacheKey || ds.cache.width() != viewW || ds.cache.height() != viewH) {
        if (ds.cache.width() != viewW || ds.cache.height() != viewH) {
          ds.cache = gpu::Framebuffer();
          ds.cache = gpu::Framebuffer::create(ds.context->ledger(), "view cache", viewW, viewH);
        }
        v.render(viewW, viewH, ds.cache.id());
        ds.cacheKey = key;
      } else if (v.refining()) {
        v.refine();  // a strip of the full-quality frame per window frame
      }
      gpu::blitFramebuffer(ds.cache.id(), {0, 0, viewW, viewH}, 0,
                           {origin.x, origin.y, viewW, viewH});
    } else {
      v.render(viewW, viewH, 0, origin);
    }
  } catch (const Error& e) {
    ds.error = e.what();
    if (ds.zoomSwap) {
      // A stage that cannot be read or uploaded: the zoom stops swapping
      // (instead of trying again every frame); the last volume stays.
      ds.zoomSwap.reset();
      ds.zoomSwitchesGrid = false;
      ds.error += " (zoom swap turned off)";
    }
  }
  const viewer::FrameStats& fs = v.lastFrame();
  char line[160];
  std::snprintf(line, sizeof line, "%s %.0f ms at %dx%d (%s)\n%s",
                v.refining() ? "refining, strip" : "frame", fs.ms, fs.renderWidth, fs.renderHeight,
                ds.context->caps().renderer.c_str(), ds.context->caps().version.c_str());
  ds.status = line;
}

// --screenshot: the window after --frames frames, then the session ends.
void takeScreenshot(DesktopSession& ds, int fbw, int fbh) {
  Image shot(fbw, fbh);
  gpu::clearErrors();  // ImGui's GL backend may leave some
  gpu::bindFramebuffer(0, {0, 0, fbw, fbh});
  gpu::readPixelsRgba8({0, 0, fbw, fbh}, shot.rgba().data());
  shot.flipVertically();
  for (std::size_t i = 3; i < shot.rgba().size(); i += 4) shot.rgba()[i] = 255;
  shot.writePng(ds.options.screenshot);
  const viewer::FrameStats& fs = ds.viewer->lastFrame();
  std::printf("wrote %s (%dx%d) after %d frames; last volume frame %.0f ms at %dx%d\n",
              ds.options.screenshot.c_str(), fbw, fbh, ds.frame, fs.ms, fs.renderWidth,
              fs.renderHeight);
  glfwSetWindowShouldClose(ds.window, 1);
}

// One pass of the event loop: input, panel, volume, ImGui, screenshot, swap.
void runFrame(DesktopSession& ds) {
  glfwPollEvents();
  if (!ds.input.pendingDrop.empty()) {
    openVolume(ds, ds.input.pendingDrop);
    ds.input.pendingDrop.clear();
  }
  int fbw = 0, fbh = 0, ww = 0, wh = 0;
  glfwGetFramebufferSize(ds.window, &fbw, &fbh);
  glfwGetWindowSize(ds.window, &ww, &wh);
  const double scale = ww > 0 ? static_cast<double>(fbw) / ww : 1.0;
  const Tiles tiles = layoutTiles(ds, ww, wh);
  // The 3D view's rectangle in framebuffer pixels (GL: origin bottom-left).
  const int vx0 = static_cast<int>(std::lround(tiles.view3d.p0.x * scale));
  const int vx1 = static_cast<int>(std::lround(tiles.view3d.p1.x * scale));
  const int vy0 = static_cast<int>(std::lround(tiles.view3d.p0.y * scale));
  const int vy1 = static_cast<int>(std::lround(tiles.view3d.p1.y * scale));
  const int viewW = std::max(1, vx1 - vx0), viewH = std::max(1, vy1 - vy0);
  ds.viewPixels = viewH;

  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  handleViewInput(ds, tiles.view3d, scale);
  handleSliceInput(ds, tiles);
  handleShortcuts(ds);
  handleExploreKeys(ds, tiles);
  updateOverlay(ds);
  drawPanel(ds, wh);
  for (int t = 0; t < 3 && ds.fourUp; ++t) drawSliceTile(ds, ds.slices[t], tiles.slice[t]);
  drawHelpOverlay(ds, kPanelWidth, static_cast<float>(ww), static_cast<float>(wh));
  const EdgeLabels labels = ds.viewer->orientationLabels();
  drawEdgeLetters(labels.left, labels.right, labels.top, labels.bottom, tiles.view3d.p0,
                  tiles.view3d.p1);
  ImGui::Render();
  gpu::bindFramebuffer(0, {0, 0, fbw, fbh});
  gpu::clearColor(glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  drawVolumeView(ds, {vx0, fbh - vy1}, viewW, viewH);
  gpu::setViewport({0, 0, fbw, fbh});
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

  ++ds.frame;
  if (!ds.options.screenshot.empty() && ds.frame >= ds.options.frames && !ds.viewer->refining()) {
    takeScreenshot(ds, fbw, fbh);
  }
  glfwSwapBuffers(ds.window);
}

// --layout, --crosshair, --pick and --mode: the exploring state to start in.
void startExploring(DesktopSession& ds, const ViewOptions& o) {
  if (o.layout != "four" && o.layout != "single") {
    throw InputError("--layout '" + o.layout + "': expected four or single");
  }
  ds.fourUp = o.layout == "four";
  if (!o.crosshair.empty()) {
    if (o.crosshair.size() != 3) throw InputError("--crosshair takes three voxel indices X Y Z");
    const glm::ivec3 c(o.crosshair[0], o.crosshair[1], o.crosshair[2]);
    const glm::ivec3 d = ds.explorer->dims();
    if (glm::any(glm::lessThan(c, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(c, d))) {
      throw InputError("--crosshair is outside the volume's voxels 0.." + std::to_string(d.x - 1) +
                       ", 0.." + std::to_string(d.y - 1) + ", 0.." + std::to_string(d.z - 1));
    }
    ds.explorer->setCrosshair(c);
  }
  if (o.regionSide > 0) ds.explorer->setRegionSide(o.regionSide);
  if (!(o.zoom > 0.0)) throw InputError("--zoom must be > 0");
  ds.viewer->camera().zoom = o.zoom;
  ds.zoomSwitchesGrid = o.zoomGrid;
  if (o.pick) ds.picked = ds.explorer->regionAt(ds.explorer->crosshair());
  if (o.mode == "region") {
    viewPickedRegion(ds);
  } else if (o.mode == "grid") {
    enterGrid(ds);
  } else if (o.mode != "overview") {
    throw InputError("--mode '" + o.mode + "': expected overview, region or grid");
  }
  if (!ds.error.empty()) throw InputError(ds.error);
  updateOverlay(ds);
}

void runView(const ViewOptions& o) {
  int width = 0, height = 0;
  parseSize(o.size, width, height);
  const gpu::DeviceProfile profile = gpu::DeviceProfile::find(o.profile);
  DesktopSession ds(o, profile.api == gpu::ApiLevel::Gles3);

  glfwSetErrorCallback([](int code, const char* what) {
    std::fprintf(stderr, "tessera view: GLFW error %d: %s\n", code, what);
  });
  if (!glfwInit()) {
    throw GpuError("GLFW cannot start: no display? (set DISPLAY, or run under xvfb-run -a)");
  }
  struct GlfwGuard {
    ~GlfwGuard() { glfwTerminate(); }
  } glfwGuard;
  ds.window = openWindow(width, height, ds.es3);
  ds.context = gpu::GlContext::adoptCurrent(profile.api, "glfw-egl");
  ds.viewer = std::make_unique<viewer::Viewer>(*ds.context, profile);
  // ES 3 keeps the frame in a cache between window frames, where a full-quality
  // frame can be refined strip by strip; ES 2 redraws every window frame.
  ds.viewer->progressive = ds.es3;
  ds.input.viewer = ds.viewer.get();
  glfwSetWindowUserPointer(ds.window, &ds.input);
  glfwSetDropCallback(ds.window, [](GLFWwindow* w, int count, const char** paths) {
    if (count > 0) static_cast<DesktopState*>(glfwGetWindowUserPointer(w))->pendingDrop = paths[0];
  });

  ds.showHelp = o.helpOverlay;
  std::string recentError;
  try {
    ds.recent.load();
  } catch (const Error& e) {
    recentError = e.what();
    std::fprintf(stderr, "tessera view: %s\n", e.what());
  }
  ds.viewer->tfEditor().setTransferFunction(TransferFunction::fromPresetOrFile(o.tf));
  openVolume(ds, o.file.empty() ? defaultVolumeSpec() : o.file);
  if (ds.error.empty()) ds.error = recentError;
  if (!ds.error.empty() && !ds.viewer->hasVolume()) throw InputError(ds.error);
  ds.viewer->camera().azimuthDeg = o.azimuth;
  ds.viewer->camera().elevationDeg = o.elevation;
  ds.viewer->settings().shading = shadingFrom(o.shading);
  ds.viewer->settings().clipping = clippingFrom(o.clipping);
  ds.showCropBox = ds.viewer->settings().clipping.cropped();
  const std::string modes[] = {"composite", "mip", "minip", "average"};  // RenderMode's order
  for (int m = 0; m < 4; ++m) {
    if (o.projection == modes[m]) ds.viewer->settings().mode = static_cast<RenderMode>(m);
  }
  startExploring(ds, o);
  if (o.labelVolume()) {
    ds.viewer->setLabels(o.labels.empty() ? render::LabelTable::defaultFor(ds.viewer->volume())
                                          : render::LabelTable::load(o.labels));
    std::snprintf(ds.labelPathBuf, sizeof ds.labelPathBuf, "%s", o.labels.c_str());
  }

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(ds.window, true);
  ImGui_ImplOpenGL3_Init(ds.es3 ? "#version 300 es" : "#version 100");
  while (!glfwWindowShouldClose(ds.window)) runFrame(ds);
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  ds.cache = gpu::Framebuffer();
  for (auto& tile : ds.slices) tile.texture = gpu::Texture();  // before the context's ledger goes
  ds.zoomSwap.reset();
  ds.viewer.reset();
  ds.context.reset();
  glfwDestroyWindow(ds.window);
}

#else

void runView(const ViewOptions&) {
  throw Error(
      "this tessera was built without the desktop viewer: install libglfw3-dev and "
      "libimgui-dev (scripts/setup.sh) and re-run cmake; or use the web viewer (scripts/web.sh)");
}

#endif

}  // namespace

void addViewCommand(CLI::App& app) {
  auto o = std::make_shared<ViewOptions>();
  CLI::App* cmd = app.add_subcommand(
      "view", "Interactive viewer: GLFW window with OpenGL ES (EGL) and the TF editor");
  cmd->add_option("file", o->file, kVolumeHelp);
  addSeriesOption(cmd, o->series);
  cmd->add_option("--tf", o->tf, "Transfer function: preset or FILE.json")->capture_default_str();
  cmd->add_option("--size", o->size, "Window size WIDTHxHEIGHT")->capture_default_str();
  o->labelsOption = cmd->add_option("--labels", o->labels,
                                    "Show a label volume (atlas) as `tessera render --labels` "
                                    "does: nearest-neighbour sampling and a categorical colour "
                                    "table instead of --tf. TABLE (optional): JSON or a label text "
                                    "file (ITK-SNAP, FreeSurfer LUT, mricron); without it a "
                                    "default palette. The Labels panel shows and hides labels")
                        ->expected(0, 1);
  cmd->add_option("--profile", o->profile,
                  "Device profile (gles3, gles2, webgl1, ...; its API level picks the context)")
      ->capture_default_str();
  cmd->add_option("--azimuth", o->azimuth, "Initial camera azimuth in degrees");
  cmd->add_option("--elevation", o->elevation, "Initial camera elevation in degrees");
  cmd->add_option("--screenshot", o->screenshot,
                  "Write the window to this PNG after --frames frames and exit");
  cmd->add_option("--frames", o->frames, "Frames before --screenshot")->capture_default_str();
  cmd->add_flag("--help-overlay", o->helpOverlay,
                "Start with the keyboard shortcuts shown (F1 or ? toggles them)");
  cmd->add_option("--layout", o->layout,
                  "four: axial, 3D, sagittal and coronal views (2x2); single: the 3D view only")
      ->capture_default_str();
  cmd->add_option("--crosshair", o->crosshair, "Start with the crosshair at voxel X Y Z (native)")
      ->expected(3);
  cmd->add_flag("--pick", o->pick,
                "Start with the region (default side: 256 or what the profile allows) picked "
                "around the crosshair");
  cmd->add_option("--zoom", o->zoom, "Initial camera zoom (1: the volume fills the view)")
      ->capture_default_str();
  cmd->add_flag("--zoom-grid", o->zoomGrid,
                "Let the zoom swap the 3D view between a coarse level, the overview level and the "
                "native grid block around the view's centre (viewer/ZoomSwap: thresholds with "
                "hysteresis, a cross-fade on ES 2 and ES 3)");
  cmd->add_option("--region-side", o->regionSide,
                  "Side of the picked region in voxels (16 .. 256 or what the profile allows)");
  cmd->add_option("--mode", o->mode,
                  "Start in: overview, region (the picked region at native resolution) or grid "
                  "(the grid view's block nearest the crosshair)")
      ->capture_default_str();
  cmd->add_option("--render-mode", o->projection,
                  "The 3D view's mode: composite, mip, minip or average (the Rendering panel's "
                  "mode)")
      ->check(CLI::IsMember({"composite", "mip", "minip", "average"}))
      ->capture_default_str();
  addShadingOptions(cmd, o->shading);
  addClippingOptions(cmd, o->clipping);
  cmd->callback([o] { runView(*o); });
}

}  // namespace tessera::app
