#include "tessera/session/Settings.h"

#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"
#include "tessera/layout/LayoutRegistry.h"
#include "tessera/render/ClippingUniforms.h"
#include "tessera/render/ShadingUniforms.h"
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/session/ChannelSettingsJson.h"

namespace tessera::session {

std::string numberText(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

namespace {

void checkOneOf(const std::string& name, const std::string& value,
                std::initializer_list<const char*> choices) {
  std::string list;
  for (const char* c : choices) {
    if (value == c) return;
    list += (list.empty() ? "" : ", ") + std::string(c);
  }
  throw InputError(name + " '" + value + "': expected one of " + list);
}

nlohmann::json vec(glm::dvec3 v) {
  return {v.x, v.y, v.z};
}

glm::dvec3 vec3From(const nlohmann::json& j, const std::string& name) {
  if (!j.is_array() || j.size() != 3) throw InputError(name + ": expected [x, y, z]");
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

const char* preintegrateText(const Sampling& s) {
  return !s.preintegrate ? "off" : s.preintegrateLitOnly ? "lit" : "on";
}

}  // namespace

bool Range::contains(double v) const {
  if (!std::isfinite(v)) return false;
  const bool aboveMin = minOpen ? v > min : v >= min;
  const bool belowMax = maxOpen ? v < max : v <= max;
  return aboveMin && belowMax;
}

std::string Range::text() const {
  return std::string(minOpen ? "(" : "[") + numberText(min) + ", " + numberText(max) +
         (maxOpen ? ")" : "]");
}

void checkRange(const std::string& name, double value, const Range& range,
                const std::string& unit) {
  if (range.contains(value)) return;
  throw InputError(name + " " + numberText(value) + ": expected " +
                   (unit.empty() ? "" : unit + " ") + "in " + range.text());
}

RenderMode parseRenderMode(const std::string& text) {
  if (const std::optional<RenderMode> mode = renderModeFromName(text)) return *mode;
  throw InputError("mode '" + text + "': expected " + renderModeChoices());
}

std::string renderModeName(RenderMode mode) {
  return std::string(renderModeToName(mode));
}

namespace {

// How a JSON value's kind reads in a message.
std::string kindOf(const nlohmann::json& j) {
  if (j.is_boolean()) return "true or false";
  if (j.is_number()) return "a number";
  if (j.is_string()) return "a string";
  if (j.is_array()) return "an array";
  if (j.is_object()) return "an object";
  return "null";
}

// fromJson reads each key as the kind its default has; a key of another
// kind is named here, found against the defaults' own JSON, so that the
// message says which one ("settings.camera.azimuth is a string, expected a
// number"). Keys the defaults lack are ignored, as fromJson ignores them.
void checkKinds(const nlohmann::json& given, const nlohmann::json& defaults,
                const std::string& where) {
  const auto scalar = [](const nlohmann::json& j) { return j.is_primitive() && !j.is_null(); };
  for (const auto& [key, value] : given.items()) {
    if (!defaults.contains(key)) continue;
    const nlohmann::json& d = defaults[key];
    const std::string at = where + "." + key;
    if (d.is_object() && value.is_object()) checkKinds(value, d, at);
    if (scalar(d) && kindOf(value) != kindOf(d)) {
      throw InputError(at + " is " + kindOf(value) + ", expected " + kindOf(d));
    }
    if (!d.is_array() || d.empty() || !scalar(d[0]) || !value.is_array()) continue;
    for (std::size_t i = 0; i < value.size(); ++i) {
      if (kindOf(value[i]) != kindOf(d[0])) {
        throw InputError(at + "[" + std::to_string(i) + "] is " + kindOf(value[i]) + ", expected " +
                         kindOf(d[0]));
      }
    }
  }
}

}  // namespace

void Settings::validate() const {
  if (!render::TechniqueRegistry::global().contains(technique)) {
    throw InputError("technique '" + technique + "': expected " +
                     render::TechniqueRegistry::global().choices());
  }
  if (layout != "auto") layout::LayoutRegistry::global().find(layout);  // names the choices
  channels.validate();
  checkRange("zoom", camera.zoom, kZoomRange);
  checkRange("fov", camera.fovYDeg, kFovRange, "degrees");
  checkRange("step", render.stepVoxels, kStepRange, "voxels");
  checkRange("max-steps", render.maxSteps, kMaxStepsRange, "samples per ray");
  checkRange("opacity-scale", render.opacityScale, kOpacityScaleRange);
  checkRange("ert", render.ertThreshold, kErtRange);
  checkRange("adaptive-tolerance", render.sampling.tolerance, kToleranceRange);
  if (render.sampling.litTolerance >= 0.0) {
    checkRange("adaptive-tolerance (lit)", render.sampling.litTolerance, kToleranceRange);
  }
  const int m = render.sampling.maxMultiplier;
  if (m < 1 || m > 64 || (m & (m - 1)) != 0) {
    throw InputError("adaptive-max " + std::to_string(m) + ": expected a power of two in 1..64");
  }
  for (int c = 0; c < 3; ++c) checkRange("background", render.background[c], kBackgroundRange);
  if (window &&
      !(std::isfinite(window->min) && std::isfinite(window->max) && window->max > window->min)) {
    throw InputError("window " + numberText(window->min) + " " + numberText(window->max) +
                     ": expected MIN < MAX, both finite (raw values)");
  }
  checkRange("skip-block", skipBlock, kSkipBlockRange, "voxels");
  if (lutSize != 256 && lutSize != 4096) {
    throw InputError("lut " + std::to_string(lutSize) + ": expected 256 or 4096 entries");
  }
  checkRange("slices", slices, kSlicesRange);
  checkOneOf("classify", classify, {"pre", "palette", "post"});
  checkOneOf("gradient", gradient, {"auto", "on-the-fly", "precomputed"});
  render::checkShading(render.shading);
  render::checkClipping(render.clipping);
}

render::TechniqueOptions Settings::techniqueOptions(glm::ivec2 imageSize) const {
  return {.imageSize = imageSize,
          .skipBlock = skipBlock,
          .lutSize = lutSize,
          .slices = slices,
          .classify = classify,
          .gradient = gradient};
}

namespace {

// The plain members of a settings struct with their JSON keys: written by
// toJson and read back by fromJson from the same table, so that the two
// cannot drift apart.
template <class T, class V>
struct Field {
  const char* key;
  V T::*member;
};
template <class T, class V>
Field(const char*, V T::*) -> Field<T, V>;  // clang 14 (emscripten) lacks aggregate deduction

template <class T, class... V>
void writeFields(nlohmann::json& j, const T& object, const Field<T, V>&... fields) {
  ((j[fields.key] = object.*fields.member), ...);
}

template <class T, class... V>
void readFields(const nlohmann::json& j, T& object, const Field<T, V>&... fields) {
  ((object.*fields.member = j.value(fields.key, object.*fields.member)), ...);
}

// Each table applies `io` (writeFields or readFields) to its struct.
template <class Json, class S, class Io>
void shadingFields(Json& j, S& d, Io io) {
  io(j, d, Field{"enabled", &Shading::enabled}, Field{"ambient", &Shading::ambient},
     Field{"diffuse", &Shading::diffuse}, Field{"specular", &Shading::specular},
     Field{"shininess", &Shading::shininess}, Field{"headlight", &Shading::headlight},
     Field{"gradient_opacity", &Shading::gradientOpacity},
     Field{"gradient_low", &Shading::gradientLow}, Field{"gradient_high", &Shading::gradientHigh});
}

template <class Json, class S, class Io>
void samplingFields(Json& j, S& sa, Io io) {
  io(j, sa, Field{"adaptive", &Sampling::adaptive}, Field{"tolerance", &Sampling::tolerance},
     Field{"lit_tolerance", &Sampling::litTolerance},
     Field{"max_multiplier", &Sampling::maxMultiplier},
     Field{"opacity_growth", &Sampling::opacityGrowth});
}

template <class Json, class S, class Io>
void renderFields(Json& j, S& r, Io io) {
  io(j, r, Field{"step", &RenderSettings::stepVoxels},
     Field{"max_steps", &RenderSettings::maxSteps},
     Field{"opacity_scale", &RenderSettings::opacityScale},
     Field{"ert", &RenderSettings::ertThreshold}, Field{"jitter", &RenderSettings::jitter},
     Field{"nearest", &RenderSettings::nearest});
}

const auto kWrite = [](auto& j, const auto& object, const auto&... fields) {
  writeFields(j, object, fields...);
};
const auto kRead = [](const auto& j, auto& object, const auto&... fields) {
  readFields(j, object, fields...);
};

}  // namespace

nlohmann::json Settings::toJson() const {
  const Shading& sh = render.shading;
  const Sampling& sa = render.sampling;
  nlohmann::json planes = nlohmann::json::array();
  for (const ClipPlane& p : render.clipping.planes) {
    planes.push_back({p.normal.x, p.normal.y, p.normal.z, p.distance});
  }
  nlohmann::json j = {
      {"version", kSettingsVersion},
      {"technique", technique},
      {"layout", layout},
      {"camera",
       {{"azimuth", camera.azimuthDeg},
        {"elevation", camera.elevationDeg},
        {"zoom", camera.zoom},
        {"fov", camera.fovYDeg},
        {"projection",
         camera.projection == Projection::Orthographic ? "orthographic" : "perspective"},
        {"target", vec(camera.target)}}},
      {"tf", nlohmann::json::parse(tf.toJson())},
      {"window", window ? nlohmann::json{window->min, window->max} : nlohmann::json(nullptr)},
      {"mode", renderModeName(render.mode)},
      {"background", {render.background.r, render.background.g, render.background.b}},
      {"sampling", {{"preintegrate", preintegrateText(sa)}}},
      {"shading", {{"light_direction", vec(sh.lightDirection)}}},
      {"clipping",
       {{"planes", planes},
        {"crop_min", vec(render.clipping.cropMin)},
        {"crop_max", vec(render.clipping.cropMax)}}},
      {"skip_block", skipBlock},
      {"lut", lutSize},
      {"slices", slices},
      {"classify", classify},
      {"gradient", gradient},
      {"labels", labels}};
  if (channels.enabled)
    j["channels"] = channelSettingsToJson(channels);  // session/ChannelSettings.h
  renderFields(j, render, kWrite);
  samplingFields(j["sampling"], sa, kWrite);
  shadingFields(j["shading"], sh, kWrite);
  return j;
}

Settings Settings::fromJson(const nlohmann::json& state) {
  if (!state.is_object()) throw InputError("session state: expected a JSON object");
  const int version = state.value("version", 0);
  if (version != kSettingsVersion) {
    throw InputError("session state version " + std::to_string(version) + ": this Tessera reads " +
                     std::to_string(kSettingsVersion));
  }
  Settings s;
  checkKinds(state, s.toJson(), "settings");
  try {
    s.technique = state.value("technique", s.technique);
    if (state.contains("channels")) s.channels = channelSettingsFromJson(state["channels"]);
    s.layout = state.value("layout", s.layout);
    if (state.contains("camera")) {
      const nlohmann::json& c = state["camera"];
      s.camera.azimuthDeg = c.value("azimuth", s.camera.azimuthDeg);
      s.camera.elevationDeg = c.value("elevation", s.camera.elevationDeg);
      s.camera.zoom = c.value("zoom", s.camera.zoom);
      s.camera.fovYDeg = c.value("fov", s.camera.fovYDeg);
      const std::string projection = c.value("projection", std::string("perspective"));
      checkOneOf("camera projection", projection, {"perspective", "orthographic"});
      s.camera.projection =
          projection == "orthographic" ? Projection::Orthographic : Projection::Perspective;
      if (c.contains("target")) s.camera.target = vec3From(c["target"], "camera target");
    }
    if (state.contains("tf")) {
      s.tfIsDefault = false;
      const nlohmann::json& tf = state["tf"];
      s.tf = tf.is_string() ? TransferFunction::fromPresetOrFile(tf.get<std::string>())
                            : TransferFunction::fromJson(tf.dump(), "session state tf");
    }
    if (state.contains("window") && !state["window"].is_null()) {
      const nlohmann::json& w = state["window"];
      if (!w.is_array() || w.size() != 2) throw InputError("window: expected [min, max]");
      s.window = ValueRange{w[0].get<double>(), w[1].get<double>()};
    }
    RenderSettings& r = s.render;
    r.mode = parseRenderMode(state.value("mode", std::string("composite")));
    renderFields(state, r, kRead);
    if (state.contains("background")) {
      const glm::dvec3 b = vec3From(state["background"], "background");
      r.background = glm::dvec4(b, 1.0);
    }
    if (state.contains("sampling")) {
      const nlohmann::json& sa = state["sampling"];
      const std::string pre = sa.value("preintegrate", std::string(preintegrateText(r.sampling)));
      checkOneOf("sampling preintegrate", pre, {"off", "on", "lit"});
      r.sampling.preintegrate = pre != "off";
      r.sampling.preintegrateLitOnly = pre == "lit";
      samplingFields(sa, r.sampling, kRead);
    }
    if (state.contains("shading")) {
      const nlohmann::json& sh = state["shading"];
      Shading& d = r.shading;
      shadingFields(sh, d, kRead);
      if (sh.contains("light_direction")) {
        d.lightDirection = vec3From(sh["light_direction"], "shading light_direction");
      }
    }
    if (state.contains("clipping")) {
      const nlohmann::json& c = state["clipping"];
      for (const nlohmann::json& p : c.value("planes", nlohmann::json::array())) {
        if (!p.is_array() || p.size() != 4)
          throw InputError("clipping plane: expected [nx, ny, nz, d]");
        r.clipping.planes.push_back(
            {{p[0].get<double>(), p[1].get<double>(), p[2].get<double>()}, p[3].get<double>()});
      }
      if (c.contains("crop_min")) r.clipping.cropMin = vec3From(c["crop_min"], "crop_min");
      if (c.contains("crop_max")) r.clipping.cropMax = vec3From(c["crop_max"], "crop_max");
    }
    s.skipBlock = state.value("skip_block", s.skipBlock);
    s.lutSize = state.value("lut", s.lutSize);
    s.slices = state.value("slices", s.slices);
    s.classify = state.value("classify", s.classify);
    s.gradient = state.value("gradient", s.gradient);
    s.labels = state.value("labels", s.labels);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(std::string("session state: ") + e.what());
  }
  s.validate();
  return s;
}

}  // namespace tessera::session
