// `tessera view [FILE]`: the desktop front end of the viewer core — a GLFW
// window with an OpenGL ES context created through EGL, Dear ImGui controls
// and the TF editor drawn over the histogram. Built when GLFW and ImGui are
// found (cmake/DesktopViewer.cmake); otherwise the command says what to install.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>

#include "app/ClippingOptions.h"
#include "app/Commands.h"
#include "app/RenderJob.h"
#include "app/ShadingOptions.h"
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
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/viewer/RecentFiles.h"
#include "tessera/viewer/Viewer.h"
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
  ShadingOptions shading;
  ClippingOptions clipping;
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

// Patient-direction letters at the middle of each edge of the 3D view (the
// region right of the panel), so sides can be checked at a glance.
void drawOrientationLabels(const EdgeLabels& labels, float x0, float x1, float height) {
  if (labels.left.empty()) return;
  ImDrawList* draw = ImGui::GetForegroundDrawList();
  const float pad = 8.0f;
  const ImU32 colour = IM_COL32(255, 230, 120, 255);
  auto put = [&](const std::string& text, float x, float y, float alignX, float alignY) {
    const ImVec2 size = ImGui::CalcTextSize(text.c_str());
    const ImVec2 at(x - alignX * size.x, y - alignY * size.y);
    draw->AddText(ImVec2(at.x + 1, at.y + 1), IM_COL32(0, 0, 0, 255), text.c_str());
    draw->AddText(at, colour, text.c_str());
  };
  const float cx = 0.5f * (x0 + x1), cy = 0.5f * height;
  put(labels.left, x0 + pad, cy, 0.0f, 0.5f);
  put(labels.right, x1 - pad, cy, 1.0f, 0.5f);
  put(labels.top, cx, pad, 0.5f, 0.0f);
  put(labels.bottom, cx, height - pad, 0.5f, 1.0f);
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
  bool logHistogram = true;
  int frame = 0;
  bool showHelp = false;
  viewer::RecentFiles recent{viewer::RecentFiles::defaultPath()};
};

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
    {"drag", "rotate"},
    {"right-drag or Shift+drag", "pan"},
    {"wheel", "zoom"},
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

// Loads a volume; an error is shown in the panel and the previous volume
// stays. Files and folders (not generated volumes) go to the recent list.
void openVolume(DesktopSession& ds, const std::string& spec) {
  try {
    ds.viewer->setVolume(readVolume(spec, {.dicomSeries = ds.options.series}), fileName(spec));
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
  if (spec.rfind("gen:", 0) == 0) return;
  try {
    std::error_code ec;
    const std::filesystem::path full = std::filesystem::absolute(spec, ec);
    ds.recent.add(ec ? spec : full.lexically_normal().string());
  } catch (const Error& e) {
    ds.error = e.what();
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

// The 3D view: mouse drags orbit (right button or shift: pan), wheel zooms.
void handleViewInput(viewer::Viewer& v, double scale) {
  ImGuiIO& io = ImGui::GetIO();
  const glm::dvec2 pos((io.MousePos.x - kPanelWidth) * scale, io.MousePos.y * scale);
  if (!io.WantCaptureMouse) {
    for (int b = 0; b < 2; ++b) {
      if (ImGui::IsMouseClicked(b) && pos.x >= 0.0) {
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
  float opacity = static_cast<float>(v.settings().opacityScale);
  if (ImGui::SliderFloat("opacity x", &opacity, 0.0f, 4.0f)) v.settings().opacityScale = opacity;
  ImGui::Checkbox("bounding box", &v.showBoundingBox);
  ImGui::SameLine();
  ImGui::Checkbox("axes", &v.showAxes);
  if (ImGui::Button("Reset view")) v.resetCamera();
}

// The crop box (fractions of each axis) and a clip plane that follows the camera.
void panelClipping(viewer::Viewer& v) {
  section("Clipping");
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
void panelShading(viewer::Viewer& v) {
  section("Shading");
  Shading& s = v.settings().shading;
  ImGui::Checkbox("shade (gradient lighting)", &s.enabled);
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
  auto slider = [](const char* label, double& value, float lo, float hi) {
    float f = static_cast<float>(value);
    if (ImGui::SliderFloat(label, &f, lo, hi)) value = f;
  };
  slider("ambient", s.ambient, 0.0f, 1.0f);
  slider("diffuse", s.diffuse, 0.0f, 1.0f);
  slider("specular", s.specular, 0.0f, 1.0f);
  slider("shininess", s.shininess, 1.0f, 128.0f);
}

// The control panel at the window's left edge.
void drawPanel(DesktopSession& ds, int windowHeight) {
  ImGui::SetNextWindowPos(ImVec2(0, 0));
  ImGui::SetNextWindowSize(ImVec2(kPanelWidth, static_cast<float>(windowHeight)));
  ImGui::Begin("Tessera", nullptr,
               ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
  panelFile(ds);
  panelTransferFunction(ds);
  panelWindowLevel(*ds.viewer);
  panelRendering(ds);
  panelShading(*ds.viewer);
  panelClipping(*ds.viewer);
  ImGui::Separator();
  ImGui::TextWrapped("%s", ds.status.c_str());
  ImGui::End();
}

// What the volume view shows; a frame is rendered only when it changes.
std::string viewKey(viewer::Viewer& v, int viewW, int viewH) {
  const Camera& c = v.camera();
  std::ostringstream key;
  key.precision(17);
  key << v.volumeName() << '|' << c.azimuthDeg << '|' << c.elevationDeg << '|' << c.zoom << '|'
      << c.target.x << c.target.y << c.target.z << '|' << v.tfEditor().revision() << '|'
      << static_cast<int>(v.settings().mode) << '|' << v.settings().stepVoxels << '|'
      << v.settings().opacityScale << '|' << v.window().min << v.window().max << '|'
      << v.technique() << static_cast<int>(v.quality) << v.controller().interacting() << '|'
      << v.showBoundingBox << v.showAxes << '|' << viewW << 'x' << viewH;
  const RenderSettings fs = v.frameSettings();
  for (const ClipPlane& p : fs.clipping.planes) {
    key << "|p" << p.normal.x << ',' << p.normal.y << ',' << p.normal.z << ',' << p.distance;
  }
  key << "|c" << fs.clipping.cropMin.x << fs.clipping.cropMin.y << fs.clipping.cropMin.z << ','
      << fs.clipping.cropMax.x << fs.clipping.cropMax.y << fs.clipping.cropMax.z;
  const Shading& sh = v.settings().shading;
  key << '|' << sh.enabled << sh.headlight << sh.lightDirection.x << ',' << sh.lightDirection.y
      << ',' << sh.lightDirection.z << '|' << sh.ambient << ',' << sh.diffuse << ',' << sh.specular
      << ',' << sh.shininess;
  return key.str();
}

// The volume right of the panel: re-rendered only when something it shows
// changed (ES 3 blits the cached frame), every frame on ES 2 (no blit).
void drawVolumeView(DesktopSession& ds, int panelPx, int viewW, int viewH) {
  viewer::Viewer& v = *ds.viewer;
  try {
    if (ds.es3) {
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
      gpu::blitFramebuffer(ds.cache.id(), {0, 0, viewW, viewH}, 0, {panelPx, 0, viewW, viewH});
    } else {
      v.render(viewW, viewH, 0, glm::ivec2(panelPx, 0));
    }
  } catch (const Error& e) {
    ds.error = e.what();
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
  const int panelPx = static_cast<int>(kPanelWidth * scale);
  const int viewW = std::max(1, fbw - panelPx), viewH = std::max(1, fbh);

  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  handleViewInput(*ds.viewer, scale);
  handleShortcuts(ds);
  drawPanel(ds, wh);
  drawHelpOverlay(ds, kPanelWidth, static_cast<float>(ww), static_cast<float>(wh));
  drawOrientationLabels(ds.viewer->orientationLabels(), kPanelWidth, static_cast<float>(ww),
                        static_cast<float>(wh));
  ImGui::Render();
  drawVolumeView(ds, panelPx, viewW, viewH);
  gpu::setViewport({0, 0, fbw, fbh});
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

  ++ds.frame;
  if (!ds.options.screenshot.empty() && ds.frame >= ds.options.frames && !ds.viewer->refining()) {
    takeScreenshot(ds, fbw, fbh);
  }
  glfwSwapBuffers(ds.window);
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
  addShadingOptions(cmd, o->shading);
  addClippingOptions(cmd, o->clipping);
  cmd->callback([o] { runView(*o); });
}

}  // namespace tessera::app
