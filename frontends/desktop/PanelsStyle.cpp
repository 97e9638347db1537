// The panels that set how the volume looks: the transfer function editor
// over the histogram, window/level, the rendering mode and sampling,
// shading, clipping and label volumes. Each edits the session's view
// (viewer::Viewer); the 3D view re-renders when its key changes
// (VolumeView.cpp). tests/desktop/PanelsStyleTest.cpp clicks these widgets
// without a window.
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "Panels.h"
#include "tessera/render/LabelTable.h"
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/session/Settings.h"

namespace tessera::desktop {

namespace {

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

// The ray step in voxels, 0.25 to 2 as on the web page: the one place the
// desktop sets and bounds it, to hand over to a session that checks the step
// for every front end.
// The slider spans the useful part of session::kStepRange; a value typed
// into it (ctrl+click) outside the range is not taken.
void stepSlider(RenderSettings& settings) {
  float step = static_cast<float>(settings.stepVoxels);
  if (ImGui::SliderFloat("step (voxels)", &step, 0.25f, 2.0f) &&
      session::kStepRange.contains(step)) {
    settings.stepVoxels = step;
  }
}

}  // namespace

void panelTransferFunction(session::Session& s, StyleUi& ui, PanelHost& host) {
  section("Transfer function");
  viewer::TransferFunctionEditor& ed = s.view().tfEditor();
  transferFunctionEditor(ed, ui.logHistogram);
  if (ImGui::BeginCombo("preset", ed.transferFunction().name.c_str())) {
    for (const std::string& name : TransferFunction::presetNames()) {
      // With its window (the look of --tf NAME).
      if (ImGui::Selectable(name.c_str())) reportErrors(host, [&] { s.choosePreset(name); });
    }
    ImGui::EndCombo();
  }
  ImGui::Checkbox("log histogram", &ui.logHistogram);
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
  ImGui::InputText("##tfpath", ui.tfPath, sizeof ui.tfPath);
  ImGui::SameLine();
  if (ImGui::Button("Save")) reportErrors(host, [&] { ed.transferFunction().save(ui.tfPath); });
  ImGui::SameLine();
  if (ImGui::Button("Load")) {
    reportErrors(host, [&] { ed.setTransferFunction(TransferFunction::load(ui.tfPath)); });
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

void panelRendering(viewer::Viewer& v, PanelHost& host) {
  section("Rendering");
  int mode = static_cast<int>(v.settings().mode);
  if (ImGui::Combo("mode", &mode, "composite\0MIP\0MinIP\0average\0")) {
    v.settings().mode = static_cast<RenderMode>(mode);
  }
  if (ImGui::BeginCombo("technique", v.technique().c_str())) {
    for (const std::string& t : render::TechniqueRegistry::global().names()) {
      if (ImGui::Selectable(t.c_str(), t == v.technique())) {
        reportErrors(host, [&] { v.setTechnique(t); });
      }
    }
    ImGui::EndCombo();
  }
  int quality = v.quality == viewer::Quality::Adaptive ? 0 : 1;
  if (ImGui::Combo("quality", &quality, "adaptive\0full\0")) {
    v.quality = quality == 0 ? viewer::Quality::Adaptive : viewer::Quality::Full;
  }
  stepSlider(v.settings());
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
void panelClipping(viewer::Viewer& v, StyleUi& ui) {
  section("Clipping");
  ImGui::Checkbox("crop box handles (drag in 3D)", &ui.showCropBox);
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

// Label volumes: on/off (the default palette), a table file, and every
// label with its colour and a visibility box (aal has 116: scrollable).
void panelLabels(viewer::Viewer& v, StyleUi& ui, PanelHost& host) {
  section("Labels");
  bool on = v.labelsOn();
  if (ImGui::Checkbox("label volume (atlas)", &on)) {
    reportErrors(host, [&] {
      if (on) {
        v.setLabelsDefault();
      } else {
        v.clearLabels();
        v.tfEditor().setTransferFunction(TransferFunction::fromPresetOrFile(ui.tf));
      }
    });
  }
  ImGui::InputText("##labeltable", ui.labelPath, sizeof ui.labelPath);
  ImGui::SameLine();
  if (ImGui::Button("load table")) {
    reportErrors(host, [&] { v.setLabels(render::LabelTable::load(ui.labelPath)); });
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

// Blinn-Phong shading (RenderSettings::shading): on/off, the light, the terms.
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

}  // namespace tessera::desktop
