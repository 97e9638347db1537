// Clinical presets (see ClinicalPresets.h). CT windows follow the usual
// reading windows (level/width in HU: soft tissue 40/400, lung -600/1500,
// bone 400/1800, angio 300/600; e.g. Radiopaedia "Windowing (CT)") widened
// so that the opacity ramps sit inside them; tissue HU from the same
// tables (air -1000, lung -900..-500, fat -100, soft tissue 20..80,
// contrast-filled vessels 150..500, cortical bone 700..3000).
//
// Names: one per preset. The HU bone preset is ct-bone-hu, as ct-bone names
// the older bone ramp over the volume's own window (TransferFunction.cpp),
// which benchmarks and scripts keep using for data that is not in HU.
#include "tessera/core/ClinicalPresets.h"

#include <algorithm>
#include <initializer_list>

#include "tessera/core/Error.h"
#include "tessera/core/Histogram.h"

namespace tessera {

namespace {

struct HuColor {
  double hu;
  glm::dvec3 rgb;
};
struct HuOpacity {
  double hu;
  double alpha;
};

// A CT preset written in HU: the points are placed in [0,1] of `window`.
ClinicalPreset ctPreset(const std::string& name, ValueRange window,
                        std::initializer_list<HuColor> colors,
                        std::initializer_list<HuOpacity> opacities) {
  ClinicalPreset p{name, "CT", TransferFunction{}, window, std::nullopt};
  p.tf.name = name;
  const auto x = [&](double hu) { return (hu - window.min) / window.width(); };
  for (const HuColor& c : colors) p.tf.addColor(x(c.hu), c.rgb);
  for (const HuOpacity& o : opacities) p.tf.addOpacity(x(o.hu), o.alpha);
  return p;
}

std::vector<ClinicalPreset> makePresets() {
  const glm::dvec3 black(0.0);
  const glm::dvec3 ivory(0.95, 0.90, 0.80);
  const glm::dvec3 white(1.0, 1.0, 0.96);
  const glm::dvec3 flesh(0.85, 0.35, 0.28);
  const glm::dvec3 red(0.80, 0.10, 0.08);
  std::vector<ClinicalPreset> out;
  out.push_back(ctPreset("ct-bone-hu", {-1000, 3000},
                         {{-1000, black}, {150, {0.75, 0.62, 0.48}}, {400, ivory}, {3000, white}},
                         {{-1000, 0.0}, {150, 0.0}, {300, 0.5}, {1000, 0.8}, {3000, 0.8}}));
  out.push_back(
      ctPreset("ct-soft-tissue", {-160, 240},
               {{-160, black}, {-100, {0.55, 0.30, 0.22}}, {40, flesh}, {200, ivory}, {240, white}},
               {{-160, 0.0}, {-100, 0.0}, {20, 0.05}, {80, 0.15}, {200, 0.8}, {240, 0.8}}));
  out.push_back(
      ctPreset("ct-lung", {-1350, 150},
               {{-1350, black},
                {-900, {0.35, 0.45, 0.60}},
                {-500, {0.70, 0.75, 0.85}},
                {0, flesh},
                {150, white}},
               {{-1350, 0.0}, {-950, 0.0}, {-900, 0.02}, {-500, 0.08}, {-200, 0.3}, {150, 0.5}}));
  out.push_back(
      ctPreset("ct-angio", {-200, 800},
               {{-200, black}, {100, red}, {300, {0.95, 0.35, 0.25}}, {600, ivory}, {800, white}},
               {{-200, 0.0}, {100, 0.0}, {250, 0.6}, {600, 0.8}, {800, 0.8}}));
  ClinicalPreset mr{"mr-percentile", "MR", TransferFunction::preset("mr-default"), std::nullopt,
                    std::make_pair(0.01, 0.99)};
  mr.tf.name = "mr-percentile";
  out.push_back(std::move(mr));
  return out;
}

}  // namespace

const std::vector<ClinicalPreset>& clinicalPresets() {
  static const std::vector<ClinicalPreset> presets = makePresets();
  return presets;
}

const ClinicalPreset& clinicalPreset(const std::string& name) {
  for (const ClinicalPreset& p : clinicalPresets()) {
    if (p.name == name) return p;
  }
  std::string names;
  for (const ClinicalPreset& p : clinicalPresets()) names += (names.empty() ? "" : ", ") + p.name;
  throw InputError("unknown clinical preset '" + name + "'; valid: " + names);
}

ValueRange clinicalWindow(const ClinicalPreset& preset, const Volume& volume) {
  if (preset.hounsfield) return *preset.hounsfield;
  if (preset.percentiles) {
    const Histogram h = Histogram::compute(volume, 4096);
    ValueRange w{h.percentile(preset.percentiles->first), h.percentile(preset.percentiles->second)};
    if (!(w.max > w.min)) w = volume.valueRange();
    return w;
  }
  return volume.window();
}

const ClinicalPreset* defaultClinicalPreset(const std::string& modality) {
  if (modality == "CT") return &clinicalPreset("ct-soft-tissue");
  if (modality == "MR") return &clinicalPreset("mr-percentile");
  return nullptr;
}

double clinicalOpacity(const ClinicalPreset& preset, const Volume& volume, double value) {
  const ValueRange w = clinicalWindow(preset, volume);
  return preset.tf.opacity(std::clamp((value - w.min) / w.width(), 0.0, 1.0));
}

}  // namespace tessera
