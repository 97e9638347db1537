// The C API of how the volume looks (frontends/web/app.js's controls): the transfer
// function and its editor, window, mode, sampling, shading and light, the
// crop box and its handles, the clip plane and label volumes. Each export
// marshals its arguments to the session (WebSession.h); the checks of the
// settings are the session's.
#include <algorithm>

#include "WebExports.h"
#include "tessera/core/Error.h"

using namespace tessera;
using web::guarded;
using web::viewerIfAny;

extern "C" {

// Transfer function: JSON in and out (the CLI's format), presets, editor gestures
// in editor units (x in [0,1], y = opacity; channel 0 opacity, 1 colour).
EMSCRIPTEN_KEEPALIVE const char* tessera_tf_json() {
  viewer::Viewer* v = viewerIfAny();
  web::scratch() = v ? v->tfEditor().json() : "";
  return web::scratch().c_str();
}
EMSCRIPTEN_KEEPALIVE int tessera_tf_set_json(const char* json) {
  return guarded([&] { web::session().viewer().tfEditor().loadJson(json); });
}
EMSCRIPTEN_KEEPALIVE int tessera_tf_preset(const char* name) {
  return guarded([&] { web::session().rendering().choosePreset(name); });  // with its window
}
EMSCRIPTEN_KEEPALIVE void tessera_tf_pointer_down(int channel, double x, double y, double rx,
                                                  double ry) {
  if (viewer::Viewer* v = viewerIfAny()) {
    v->tfEditor().pointerDown(channel == 1 ? viewer::TfChannel::Color : viewer::TfChannel::Opacity,
                              {x, y}, {rx, ry});
  }
}
EMSCRIPTEN_KEEPALIVE void tessera_tf_pointer_move(double x, double y) {
  if (viewer::Viewer* v = viewerIfAny()) v->tfEditor().pointerMove({x, y});
}
EMSCRIPTEN_KEEPALIVE void tessera_tf_pointer_up(double x, double y) {
  if (viewer::Viewer* v = viewerIfAny()) v->tfEditor().pointerUp({x, y});
}
EMSCRIPTEN_KEEPALIVE int tessera_tf_remove_selected() {
  viewer::Viewer* v = viewerIfAny();
  return v && v->tfEditor().removeSelected() ? 1 : 0;
}
EMSCRIPTEN_KEEPALIVE void tessera_tf_set_selected_color(double r, double g, double b) {
  if (viewer::Viewer* v = viewerIfAny()) v->tfEditor().setSelectedColor(glm::dvec3(r, g, b));
}

// Render settings.
EMSCRIPTEN_KEEPALIVE int tessera_set_window(double min, double max) {
  return guarded([&] { web::session().viewer().setWindow({min, max}); });
}
EMSCRIPTEN_KEEPALIVE void tessera_reset_window() {
  if (viewer::Viewer* v = viewerIfAny()) v->resetWindow();
}
// 0 composite, 1 MIP, 2 MinIP, 3 average (RenderMode's order).
EMSCRIPTEN_KEEPALIVE void tessera_set_mode(int mode) {
  viewer::Viewer* v = viewerIfAny();
  if (v && mode >= 0 && mode <= 3) v->settings().mode = static_cast<RenderMode>(mode);
}
EMSCRIPTEN_KEEPALIVE int tessera_set_step(double voxels) {
  return guarded([&] { web::session().setStep(voxels); });
}
// Pre-integrated classification and adaptive steps (RenderSettings.h: the
// page starts with the session's default sampling), each on (1) or off (0).
EMSCRIPTEN_KEEPALIVE void tessera_set_sampling(int preintegrate, int adaptive) {
  viewer::Viewer* v = viewerIfAny();
  if (!v) return;
  v->settings().sampling.preintegrate = preintegrate != 0;
  v->settings().sampling.preintegrateLitOnly = false;
  v->settings().sampling.adaptive = adaptive != 0;
}
// Blinn-Phong shading with a headlight and the default terms (RenderSettings::shading).
EMSCRIPTEN_KEEPALIVE void tessera_set_shading(int on) {
  if (viewer::Viewer* v = viewerIfAny()) v->settings().shading.enabled = on != 0;
}
EMSCRIPTEN_KEEPALIVE void tessera_set_opacity_scale(double s) {
  viewer::Viewer* v = viewerIfAny();
  if (v && s >= 0.0) v->settings().opacityScale = s;
}
EMSCRIPTEN_KEEPALIVE void tessera_set_overlays(int box, int axes) {
  viewer::Viewer* v = viewerIfAny();
  if (!v) return;
  v->showBoundingBox = box != 0;
  v->showAxes = axes != 0;
}
// The most volume pixels a frame renders (0: the canvas's own); the canvas
// keeps its backing size (CSS size x devicePixelRatio) for lines and compositing.
EMSCRIPTEN_KEEPALIVE void tessera_set_max_volume_pixels(int pixels) {
  if (viewer::Viewer* v = viewerIfAny()) v->maxVolumePixels = std::max(0, pixels);
}
EMSCRIPTEN_KEEPALIVE void tessera_set_quality(int adaptive) {
  if (viewer::Viewer* v = viewerIfAny()) {
    v->quality = adaptive ? viewer::Quality::Adaptive : viewer::Quality::Full;
  }
}
// The frame time (ms) adaptive quality aims at while the user drags. The
// browser composes the page after each frame, on the same (software) GPU
// on phones without one, so the page asks for less than the viewer's own
// goal to keep the drag's frame rate.
EMSCRIPTEN_KEEPALIVE void tessera_set_interaction_goal(double ms) {
  viewer::Viewer* v = viewerIfAny();
  if (!v || !(ms > 0.0)) return;
  render::QualityController::Options options = v->qualityController().options();
  options.goalMs = ms;
  v->qualityController() = render::QualityController(options);
}
EMSCRIPTEN_KEEPALIVE int tessera_set_technique(const char* name) {
  return guarded([&] { web::session().viewer().setTechnique(name); });
}

// Blinn-Phong terms and the light: a headlight, or a fixed light from
// (lx, ly, lz) in the patient frame (RAS+, towards the light).
EMSCRIPTEN_KEEPALIVE int tessera_set_light(int headlight, double ambient, double diffuse,
                                           double specular, double shininess, double lx, double ly,
                                           double lz) {
  return guarded([&] {
    web::session().setLight(headlight != 0, ambient, diffuse, specular, shininess, {lx, ly, lz});
  });
}

// Gradient-magnitude opacity modulation (Shading::gradientOpacity): opacity
// times clamp((|g| - low) / (high - low), 0, 1), with or without the light
// (`tessera render --gradient-opacity on|LOW,HIGH`).
EMSCRIPTEN_KEEPALIVE int tessera_set_gradient_opacity(int on, double low, double high) {
  return guarded([&] { web::session().setGradientOpacity(on != 0, low, high); });
}

// The crop box in fractions of each index axis (0..1, min < max).
EMSCRIPTEN_KEEPALIVE int tessera_set_crop(double x0, double x1, double y0, double y1, double z0,
                                          double z1) {
  return guarded([&] { web::session().setCrop({x0, y0, z0}, {x1, y1, z1}); });
}
EMSCRIPTEN_KEEPALIVE void tessera_show_crop_box(int on) {
  web::WebSession* s = web::sessionIfAny();
  if (!s) return;
  s->crop().show = on != 0;
  s->refreshExtraLines();
}
// The crop box as JSON {"min": [x, y, z], "max": [...], "handles": [[px,
// py] per face (-x, +x, -y, +y, -z, +z) on a width x height canvas]}.
EMSCRIPTEN_KEEPALIVE const char* tessera_crop_json(int width, int height) {
  nlohmann::json j;
  web::WebSession* s = web::sessionIfAny();
  if (!s) return web::jsonOut(j);
  viewer::Viewer& v = s->viewer();
  const Clipping& c = v.settings().clipping;
  if (v.hasVolume() && width > 0 && height > 0) {
    j["handles"] = nlohmann::json::array();
    for (int f = 0; f < viewer::kCropFaces; ++f) {
      const auto p = viewer::projectToScreen(
          v.camera(), viewer::CropHandles::faceCentre(c, v.volume().extent(), f), width, height);
      j["handles"].push_back(p ? nlohmann::json{p->pixel.x, p->pixel.y} : nlohmann::json());
    }
  }
  j["min"] = {c.cropMin.x, c.cropMin.y, c.cropMin.z};
  j["max"] = {c.cropMax.x, c.cropMax.y, c.cropMax.z};
  j["show"] = s->crop().show;
  const auto dragging = s->crop().handles.dragging();
  j["dragging"] = dragging ? *dragging : -1;
  return web::jsonOut(j);
}
// A pointer pressed at canvas pixel (x, y) of a width x height canvas: 1 when
// it grabbed a crop box handle (the page then sends moves here, not to the
// camera), else 0.
EMSCRIPTEN_KEEPALIVE int tessera_crop_pointer_down(double x, double y, int width, int height,
                                                   double radiusPx) {
  web::WebSession* s = web::sessionIfAny();
  if (!s || !s->crop().show || !s->viewer().hasVolume()) return 0;
  viewer::Viewer& v = s->viewer();
  const glm::dvec3 extent = v.volume().extent();
  const auto face = viewer::CropHandles::hit(v.camera(), v.settings().clipping, extent, {x, y},
                                             width, height, radiusPx);
  if (!face) return 0;
  s->crop().handles.begin(v.camera(), v.settings().clipping, extent, *face, {x, y}, width, height);
  s->refreshExtraLines();
  return 1;
}
// 1 when the box changed.
EMSCRIPTEN_KEEPALIVE int tessera_crop_pointer_move(double x, double y) {
  web::WebSession* s = web::sessionIfAny();
  if (!s) return 0;
  const bool changed = s->crop().handles.move({x, y}, s->viewer().settings().clipping);
  if (changed) s->refreshExtraLines();
  return changed ? 1 : 0;
}
EMSCRIPTEN_KEEPALIVE void tessera_crop_pointer_up() {
  web::WebSession* s = web::sessionIfAny();
  if (!s) return;
  s->crop().handles.end();
  s->refreshExtraLines();
}
// The clip plane that follows the camera (viewer::cameraFacingPlane), at
// `depth` x half the volume's diagonal from its centre towards the viewer
// (-1..1: the whole volume).
EMSCRIPTEN_KEEPALIVE void tessera_set_following_plane(int on, double depth) {
  if (web::WebSession* s = web::sessionIfAny()) s->setFollowingPlane(on != 0, depth);
}

// Label volumes (atlases), as `tessera render --labels` shows them
// (viewer::Viewer::setLabels). on = 0: an ordinary volume again (the TF
// preset `mr-default`). on = 1: labels, with `table` (the file's text, named
// `name`; errors name the file and line) or, when empty, the default
// palette. 0 on error (tessera_last_error), the state unchanged.
EMSCRIPTEN_KEEPALIVE int tessera_set_labels(int on, const char* table, const char* name) {
  return guarded([&] { web::session().setLabels(on != 0, table, name); });
}
// {"on": bool, "labels": [{"value", "name", "color": [r, g, b] 0..1, "visible"}]}
EMSCRIPTEN_KEEPALIVE const char* tessera_labels_json() {
  nlohmann::json j;
  viewer::Viewer* v = viewerIfAny();
  const bool on = v && v->labelsOn();
  j["on"] = on;
  j["labels"] = nlohmann::json::array();
  if (on) {
    for (const auto& [value, label] : v->labelTable().labels) {
      j["labels"].push_back({{"value", value},
                             {"name", label.name},
                             {"color", {label.color.r, label.color.g, label.color.b}},
                             {"visible", label.visible}});
    }
  }
  return web::jsonOut(j);
}
// value < 0: every label.
EMSCRIPTEN_KEEPALIVE void tessera_set_label_visible(int value, int visible) {
  viewer::Viewer* v = viewerIfAny();
  if (!v) return;
  if (value < 0) {
    v->setAllLabelsVisible(visible != 0);
  } else {
    v->setLabelVisible(value, visible != 0);
  }
}

}  // extern "C"
