#pragma once
// Piecewise-linear transfer function on normalised scalars n in [0,1]
// (n = the value through the volume's window). Colour and opacity have their
// own control points. Opacity is "per opacityUnitLength world units": the
// opacity a slab of that thickness has; a sample that represents a length ds
// gets a = 1 - (1 - a0)^(ds / unit) (DESIGN.md, Rendering semantics).
#include <filesystem>
#include <initializer_list>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace tessera {

struct ColorPoint {
  double x = 0.0;       // normalised scalar, [0,1]
  glm::dvec3 rgb{0.0};  // each in [0,1]
};

struct OpacityPoint {
  double x = 0.0;      // normalised scalar, [0,1]
  double alpha = 0.0;  // [0,1], per opacityUnitLength
};

class TransferFunction {
 public:
  std::string name = "custom";
  // Control points, kept sorted by x. Outside the first/last point the
  // end value holds (clamp). An empty list means black / transparent.
  std::vector<ColorPoint> colors;
  std::vector<OpacityPoint> opacities;
  // World length (e.g. mm) over which an opacity value accumulates.
  double opacityUnitLength = 1.0;

  void addColor(double x, glm::dvec3 rgb);  // inserts sorted
  void addOpacity(double x, double alpha);  // inserts sorted
  // A function called `name` with these points, added in order (the checks
  // and sorting of addColor and addOpacity).
  static TransferFunction fromPoints(std::string name, std::initializer_list<ColorPoint> colors,
                                     std::initializer_list<OpacityPoint> opacities);

  glm::dvec3 color(double x) const;
  double opacity(double x) const;
  // (r, g, b, opacity) — not premultiplied, opacity uncorrected.
  glm::dvec4 evaluate(double x) const;

  // Opacity of one sample representing `sampleDistance` world units, after
  // the global opacity scale (Schultz 2016, 7.2.7's user alpha) and the
  // distance correction: a = 1 - (1 - clamp(a0*scale,0,1))^(ds/unit).
  double correctedOpacity(double x, double sampleDistance, double opacityScale) const;

  // Lookup table of `entries` RGBA floats (4 per entry; entry i is x = i/(entries-1)),
  // opacity already corrected for `sampleDistance` and scaled by `opacityScale`;
  // colour not premultiplied. entries must be 256 or 4096 (InputError otherwise).
  std::vector<float> bake(int entries, double sampleDistance, double opacityScale) const;

  // Named presets: those on the volume's own window ("grey", "mr-default",
  // "ct-bone", "ct-muscle", "bench"), then the clinical presets of
  // core/ClinicalPresets.h whose names those leave free ("ct-soft-tissue",
  // "ct-lung", "ct-angio", "mr-percentile"): their TF here, their window
  // (HU, percentiles) put on the volume by the session.
  static TransferFunction preset(const std::string& name);  // InputError if unknown
  static std::vector<std::string> presetNames();
  static std::vector<std::string> windowPresetNames();

  // JSON: {"name": s, "opacity_unit_length": u,
  //        "color": [{"x": 0, "rgb": [r,g,b]}, ...],
  //        "opacity": [{"x": 0, "alpha": a}, ...]}
  std::string toJson() const;
  static TransferFunction fromJson(const std::string& text, const std::string& what = "JSON");
  void save(const std::filesystem::path& path) const;
  static TransferFunction load(const std::filesystem::path& path);  // InputError names the file
  // A preset name or a path to a .json file.
  static TransferFunction fromPresetOrFile(const std::string& spec);
};

}  // namespace tessera
