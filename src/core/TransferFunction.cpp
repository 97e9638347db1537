#include "tessera/core/TransferFunction.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <sstream>
#include <utility>

#include <nlohmann/json.hpp>

#include "tessera/core/ClinicalPresets.h"
#include "tessera/core/Error.h"

namespace tessera {

namespace {

using nlohmann::json;

bool inUnit(double v) {
  return std::isfinite(v) && v >= 0.0 && v <= 1.0;
}

// Shortest text that reads back as `v` ("0.1", not "0.10000000000000001").
std::string num(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

void requireUnit(double v, const std::string& what, const std::string& field) {
  if (!inUnit(v)) {
    throw InputError(what + ": " + field + " is " + num(v) + ", expected a number in [0, 1]");
  }
}

// Piecewise-linear interpolation over points sorted by x; `value(p)` extracts
// the interpolated quantity. Points with equal x make a step: upper_bound
// picks the last of them, so the function is right-continuous there.
template <class Point, class Get>
auto interpolate(const std::vector<Point>& points, double x, Get value) {
  using T = decltype(value(points.front()));
  if (points.empty()) return T(0.0);
  // `!(x >= front)` also sends NaN to the first point instead of propagating it.
  if (!(x >= points.front().x)) return value(points.front());
  if (x >= points.back().x) return value(points.back());
  auto hi = std::upper_bound(points.begin(), points.end(), x,
                             [](double v, const Point& p) { return v < p.x; });
  auto lo = std::prev(hi);
  const double t = (x - lo->x) / (hi->x - lo->x);
  return value(*lo) + (value(*hi) - value(*lo)) * t;
}

const json& field(const json& object, const char* key, const std::string& where) {
  auto it = object.find(key);
  if (it == object.end()) throw InputError(where + ": missing \"" + key + "\"");
  return *it;
}

double numberField(const json& object, const char* key, const std::string& where) {
  const json& v = field(object, key, where);
  if (!v.is_number()) {
    throw InputError(where + ": \"" + key + "\": expected a number, got " + v.dump());
  }
  return v.get<double>();
}

void rejectUnknownKeys(const json& object, std::initializer_list<const char*> known,
                       const std::string& where) {
  for (auto it = object.begin(); it != object.end(); ++it) {
    if (std::none_of(known.begin(), known.end(), [&](const char* k) { return it.key() == k; })) {
      std::string list;
      for (const char* k : known) list += std::string(list.empty() ? "" : ", ") + "\"" + k + "\"";
      // A misspelt key would otherwise be ignored silently and its value lost.
      throw InputError(where + ": unknown key \"" + it.key() + "\" (expected " + list + ")");
    }
  }
}

struct Preset {
  const char* name;
  TransferFunction (*make)();
};

TransferFunction makeGrey() {
  return TransferFunction::fromPoints("grey",
                                      {
                                          {0.0, {0.0, 0.0, 0.0}},
                                          {1.0, {1.0, 1.0, 1.0}},
                                      },
                                      {{0.0, 0.0}, {1.0, 0.05}});
}

// The benchmark TF: transparent up to 20 % of the range, then opacity rising
// linearly to 0.2 per unit length (one voxel at spacing 1) at the maximum.
TransferFunction makeBench() {
  return TransferFunction::fromPoints("bench",
                                      {
                                          {0.0, {0.0, 0.0, 0.0}},
                                          {1.0, {1.0, 1.0, 1.0}},
                                      },
                                      {{0.0, 0.0}, {0.2, 0.0}, {1.0, 0.2}});
}

// For a T1 MRI head such as mricron's ch2 (u8, window 0..254): air and noise
// sit below ~0.08, CSF ~0.1-0.2, grey/white matter ~0.3-0.45, scalp fat up to
// 1. Opacity starts at 0.12 so that the first tissue a ray meets is the skin,
// and reaches ~0.1 per mm within a few grey levels of it: with 0.5 mm steps a
// few millimetres of scalp are nearly opaque, which gives a recognisable face.
TransferFunction makeMrDefault() {
  return TransferFunction::fromPoints(
      "mr-default",
      {
          {0.0, {0.0, 0.0, 0.0}},
          {0.12, {0.55, 0.30, 0.22}},
          {0.25, {0.85, 0.58, 0.46}},
          {0.45, {0.95, 0.76, 0.64}},
          {0.70, {1.00, 0.90, 0.82}},
          {1.0, {1.0, 1.0, 1.0}},
      },
      {{0.0, 0.0}, {0.12, 0.0}, {0.20, 0.12}, {0.45, 0.20}, {1.0, 0.30}});
}

// Bone only: soft tissue (below ~0.45 of the window) is invisible; the
// ivory-to-white ramp and the steep opacity ramp above 0.45 show the skull
// as a surface.
TransferFunction makeCtBone() {
  return TransferFunction::fromPoints("ct-bone",
                                      {
                                          {0.0, {0.0, 0.0, 0.0}},
                                          {0.45, {0.75, 0.62, 0.48}},
                                          {0.60, {0.95, 0.90, 0.80}},
                                          {1.0, {1.0, 1.0, 0.96}},
                                      },
                                      {{0.0, 0.0}, {0.45, 0.0}, {0.60, 0.5}, {1.0, 0.8}});
}

// Soft tissue as a semi-transparent red/pink shell (0.3-0.5) in front of
// opaque white bone (above ~0.6).
TransferFunction makeCtMuscle() {
  return TransferFunction::fromPoints(
      "ct-muscle",
      {
          {0.0, {0.0, 0.0, 0.0}},
          {0.25, {0.55, 0.12, 0.08}},
          {0.35, {0.85, 0.30, 0.25}},
          {0.50, {0.95, 0.55, 0.50}},
          {0.60, {0.95, 0.90, 0.82}},
          {1.0, {1.0, 1.0, 1.0}},
      },
      {{0.0, 0.0}, {0.25, 0.0}, {0.35, 0.04}, {0.50, 0.08}, {0.55, 0.08}, {0.65, 0.6}, {1.0, 0.8}});
}

constexpr Preset kPresets[] = {
    {"grey", makeGrey},          {"mr-default", makeMrDefault}, {"ct-bone", makeCtBone},
    {"ct-muscle", makeCtMuscle}, {"bench", makeBench},
};

std::string presetList() {
  std::string s;
  for (const std::string& name : TransferFunction::presetNames()) {
    s += (s.empty() ? "" : ", ") + name;
  }
  return s;
}

// A clinical preset (ClinicalPresets.h) that no window preset shadows: its
// TF, whose window the session puts on the volume (session/ModalityDefault.h).
const TransferFunction* clinicalTf(const std::string& name) {
  for (const Preset& p : kPresets) {
    if (name == p.name) return nullptr;
  }
  for (const ClinicalPreset& c : clinicalPresets()) {
    if (c.name == name) return &c.tf;
  }
  return nullptr;
}

bool endsWithJson(const std::string& s) {
  if (s.size() < 5) return false;
  std::string tail = s.substr(s.size() - 5);
  std::transform(tail.begin(), tail.end(), tail.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return tail == ".json";
}

}  // namespace

TransferFunction TransferFunction::fromPoints(std::string name,
                                              std::initializer_list<ColorPoint> colors,
                                              std::initializer_list<OpacityPoint> opacities) {
  TransferFunction tf;
  tf.name = std::move(name);
  for (const ColorPoint& p : colors) tf.addColor(p.x, p.rgb);
  for (const OpacityPoint& p : opacities) tf.addOpacity(p.x, p.alpha);
  return tf;
}

void TransferFunction::addColor(double x, glm::dvec3 rgb) {
  requireUnit(x, "addColor", "x");
  for (int c = 0; c < 3; ++c) requireUnit(rgb[c], "addColor", "rgb[" + std::to_string(c) + "]");
  // upper_bound: a point at an existing x goes after it, so adding two points
  // at one x in order makes a step.
  auto at = std::upper_bound(colors.begin(), colors.end(), x,
                             [](double v, const ColorPoint& p) { return v < p.x; });
  colors.insert(at, ColorPoint{x, rgb});
}

void TransferFunction::addOpacity(double x, double alpha) {
  requireUnit(x, "addOpacity", "x");
  requireUnit(alpha, "addOpacity", "alpha");
  auto at = std::upper_bound(opacities.begin(), opacities.end(), x,
                             [](double v, const OpacityPoint& p) { return v < p.x; });
  opacities.insert(at, OpacityPoint{x, alpha});
}

glm::dvec3 TransferFunction::color(double x) const {
  return interpolate(colors, x, [](const ColorPoint& p) { return p.rgb; });
}

double TransferFunction::opacity(double x) const {
  return interpolate(opacities, x, [](const OpacityPoint& p) { return p.alpha; });
}

glm::dvec4 TransferFunction::evaluate(double x) const {
  return {color(x), opacity(x)};
}

double TransferFunction::correctedOpacity(double x, double sampleDistance,
                                          double opacityScale) const {
  // Opacity correction for sample distance (Engel et al., Real-Time Volume
  // Graphics, eq. 9.2; DESIGN.md): a slab of length ds transmits
  // (1 - a0)^(ds / unit) of the light that a slab of length `unit` would.
  const double a0 = std::clamp(opacity(x) * opacityScale, 0.0, 1.0);
  return 1.0 - std::pow(1.0 - a0, sampleDistance / opacityUnitLength);
}

std::vector<float> TransferFunction::bake(int entries, double sampleDistance,
                                          double opacityScale) const {
  if (entries != 256 && entries != 4096) {
    throw InputError("transfer function '" + name + "': lookup table size " +
                     std::to_string(entries) + " is not supported, expected 256 or 4096");
  }
  if (!std::isfinite(sampleDistance) || sampleDistance < 0.0) {
    throw InputError("transfer function '" + name + "': sample distance " + num(sampleDistance) +
                     " must be finite and >= 0");
  }
  if (!std::isfinite(opacityScale) || opacityScale < 0.0) {
    throw InputError("transfer function '" + name + "': opacity scale " + num(opacityScale) +
                     " must be finite and >= 0");
  }
  std::vector<float> table(static_cast<std::size_t>(entries) * 4);
  for (int i = 0; i < entries; ++i) {
    const double x = static_cast<double>(i) / (entries - 1);
    const glm::dvec3 c = color(x);
    float* e = &table[static_cast<std::size_t>(i) * 4];
    e[0] = static_cast<float>(c.r);
    e[1] = static_cast<float>(c.g);
    e[2] = static_cast<float>(c.b);
    e[3] = static_cast<float>(correctedOpacity(x, sampleDistance, opacityScale));
  }
  return table;
}

TransferFunction TransferFunction::preset(const std::string& presetName) {
  for (const Preset& p : kPresets) {
    if (presetName == p.name) return p.make();
  }
  if (const TransferFunction* tf = clinicalTf(presetName)) return *tf;
  throw InputError("unknown transfer-function preset '" + presetName +
                   "'; valid presets: " + presetList());
}

std::vector<std::string> TransferFunction::presetNames() {
  std::vector<std::string> names = windowPresetNames();
  for (const ClinicalPreset& c : clinicalPresets()) {
    if (clinicalTf(c.name)) names.push_back(c.name);
  }
  return names;
}

std::vector<std::string> TransferFunction::windowPresetNames() {
  std::vector<std::string> names;
  for (const Preset& p : kPresets) names.emplace_back(p.name);
  return names;
}

std::string TransferFunction::toJson() const {
  // Written by hand to keep one control point per line, which keeps
  // hand-edited files readable. Values still go through nlohmann: it writes
  // the shortest decimal that parses back to the same double, so save/load
  // preserves every control point bit for bit, and it escapes the name.
  const auto number = [](double v) { return json(v).dump(); };
  std::string s =
      "{\n  \"name\": " + json(name).dump(-1, ' ', false, json::error_handler_t::replace) +
      ",\n  \"opacity_unit_length\": " + number(opacityUnitLength) + ",\n  \"color\": [";
  for (std::size_t i = 0; i < colors.size(); ++i) {
    const ColorPoint& p = colors[i];
    s += std::string(i == 0 ? "\n" : ",\n") + "    {\"x\": " + number(p.x) + ", \"rgb\": [" +
         number(p.rgb.r) + ", " + number(p.rgb.g) + ", " + number(p.rgb.b) + "]}";
  }
  s += "\n  ],\n  \"opacity\": [";
  for (std::size_t i = 0; i < opacities.size(); ++i) {
    const OpacityPoint& p = opacities[i];
    s += std::string(i == 0 ? "\n" : ",\n") + "    {\"x\": " + number(p.x) +
         ", \"alpha\": " + number(p.alpha) + "}";
  }
  s += "\n  ]\n}\n";
  return s;
}

TransferFunction TransferFunction::fromJson(const std::string& text, const std::string& what) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {
    throw InputError(what + ": not valid JSON: " + e.what());
  }
  if (!j.is_object()) throw InputError(what + ": expected a JSON object at the top level");
  rejectUnknownKeys(j, {"name", "opacity_unit_length", "color", "opacity"}, what);

  TransferFunction tf;
  if (auto it = j.find("name"); it != j.end()) {
    if (!it->is_string()) throw InputError(what + ": name: expected a string, got " + it->dump());
    tf.name = it->get<std::string>();
  }
  if (j.contains("opacity_unit_length")) {
    tf.opacityUnitLength = numberField(j, "opacity_unit_length", what);
    if (!std::isfinite(tf.opacityUnitLength) || tf.opacityUnitLength <= 0.0) {
      throw InputError(what + ": opacity_unit_length is " + num(tf.opacityUnitLength) +
                       ", expected a finite number > 0");
    }
  }

  const json& cs = field(j, "color", what);
  if (!cs.is_array() || cs.empty()) {
    throw InputError(what + ": color: expected a non-empty array of {\"x\", \"rgb\"} points");
  }
  for (std::size_t i = 0; i < cs.size(); ++i) {
    const std::string where = what + ": color[" + std::to_string(i) + "]";
    if (!cs[i].is_object()) throw InputError(where + ": expected an object");
    rejectUnknownKeys(cs[i], {"x", "rgb"}, where);
    ColorPoint p;
    p.x = numberField(cs[i], "x", where);
    requireUnit(p.x, where, "x");
    const json& rgb = field(cs[i], "rgb", where);
    if (!rgb.is_array() || rgb.size() != 3) {
      throw InputError(where + ": rgb: expected an array of 3 numbers, got " + rgb.dump());
    }
    for (int c = 0; c < 3; ++c) {
      if (!rgb[c].is_number()) {
        throw InputError(where + ": rgb: expected an array of 3 numbers, got " + rgb.dump());
      }
      p.rgb[c] = rgb[c].get<double>();
      requireUnit(p.rgb[c], where, "rgb[" + std::to_string(c) + "]");
    }
    tf.colors.push_back(p);
  }

  const json& os = field(j, "opacity", what);
  if (!os.is_array() || os.empty()) {
    throw InputError(what + ": opacity: expected a non-empty array of {\"x\", \"alpha\"} points");
  }
  for (std::size_t i = 0; i < os.size(); ++i) {
    const std::string where = what + ": opacity[" + std::to_string(i) + "]";
    if (!os[i].is_object()) throw InputError(where + ": expected an object");
    rejectUnknownKeys(os[i], {"x", "alpha"}, where);
    OpacityPoint p;
    p.x = numberField(os[i], "x", where);
    requireUnit(p.x, where, "x");
    p.alpha = numberField(os[i], "alpha", where);
    requireUnit(p.alpha, where, "alpha");
    tf.opacities.push_back(p);
  }

  // Files may list points in any order; a stable sort keeps the order of
  // points sharing an x, which is what defines a step there.
  std::stable_sort(tf.colors.begin(), tf.colors.end(),
                   [](const ColorPoint& a, const ColorPoint& b) { return a.x < b.x; });
  std::stable_sort(tf.opacities.begin(), tf.opacities.end(),
                   [](const OpacityPoint& a, const OpacityPoint& b) { return a.x < b.x; });
  return tf;
}

void TransferFunction::save(const std::filesystem::path& path) const {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(path.string() + ": cannot open for writing");
  out << toJson();
  out.close();
  if (!out) throw Error(path.string() + ": writing the transfer function failed");
}

TransferFunction TransferFunction::load(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open transfer function file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(path.string() + ": reading the transfer function file failed");
  return fromJson(text.str(), path.string());
}

TransferFunction TransferFunction::fromPresetOrFile(const std::string& spec) {
  for (const std::string& name : presetNames()) {
    if (spec == name) return preset(name);
  }
  if (endsWithJson(spec)) return load(spec);
  throw InputError("transfer function '" + spec + "' is neither a preset (" + presetList() +
                   ") nor a .json file");
}

}  // namespace tessera
