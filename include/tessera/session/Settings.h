#pragma once
// Everything a rendering session is set to — technique and layout wishes,
// camera, transfer function, window, sampling, shading, clipping, mode,
// labels — in one type, checked in one place (validate()) against one range
// per number, with one message per setting. Every front end fills it from
// its own input (CLI options, sliders, the page's controls, Python keyword
// arguments) and takes its controls' limits from the ranges below; none
// checks a setting itself. As JSON (one versioned schema) it is what a front
// end saves and restores.
#include <optional>
#include <string>

#include <glm/vec2.hpp>
#include <nlohmann/json_fwd.hpp>

#include "tessera/core/Camera.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/core/Volume.h"
#include "tessera/render/Technique.h"
#include "tessera/session/ChannelSettings.h"

namespace tessera::session {

// A closed or half-open interval of a numeric setting, for checks and for
// the limits of a front end's control.
struct Range {
  double min = 0.0;
  double max = 0.0;
  bool minOpen = false;  // (min, max] instead of [min, max]
  bool maxOpen = false;
  bool contains(double v) const;
  std::string text() const;  // "(0, 8]"
};

// The one range of each numeric setting.
inline constexpr Range kStepRange{0.0, 8.0, true, false};  // voxels of the smallest spacing
inline constexpr Range kZoomRange{0.0, 1.0e4, true, false};
inline constexpr Range kFovRange{0.0, 180.0, true, true};  // degrees
inline constexpr Range kMaxStepsRange{1.0, 1 << 20, false, false};
inline constexpr Range kOpacityScaleRange{0.0, 1.0e3, false, false};
inline constexpr Range kErtRange{0.0, 1.0e9, false, false};  // >= 1 disables early termination
inline constexpr Range kToleranceRange{0.0, 1.0e9, false, false};
inline constexpr Range kBackgroundRange{0.0, 1.0, false, false};
inline constexpr Range kSkipBlockRange{0.0, 256.0, false, false};
inline constexpr Range kSlicesRange{0.0, 1 << 16, false, false};

// A number as messages and notes show it ("%g": 0.5, 1024, 1e+06).
std::string numberText(double v);

// InputError "NAME VALUE: expected UNIT in RANGE" unless the range holds it.
void checkRange(const std::string& name, double value, const Range& range,
                const std::string& unit = "");

struct Settings {
  // Names in render::TechniqueRegistry and layout::LayoutRegistry ("auto":
  // the planner chooses).
  std::string technique = "raycast";
  std::string layout = "auto";
  // Azimuth, elevation, zoom, field of view, projection, pan; the radius is
  // set when the camera frames a volume.
  Camera camera;
  TransferFunction tf = TransferFunction::preset("mr-default");
  // Raw values mapped to the TF's [0,1]; none: the volume's own window.
  std::optional<ValueRange> window;
  // `tf` is the front end's default, not the user's: opening a volume with
  // a modality replaces it by that modality's default
  // (session/ModalityDefault.h). Not saved: a state's TF is the user's.
  bool tfIsDefault = true;
  // Mode, step, sampling, shading, clipping, opacity, ERT, background.
  RenderSettings render = defaultRenderSettings();
  // Technique options (render::TechniqueOptions).
  int skipBlock = 8;
  int lutSize = 4096;
  int slices = 0;
  std::string classify = "post";
  std::string gradient = "auto";
  // A label volume (atlas): nearest sampling and the label table's TF.
  bool labels = false;

  // Throws InputError naming the first setting out of its range or unknown.
  // Several channels of a store together (session/ChannelSettings.h).
  ChannelSettings channels;

  void validate() const;
  render::TechniqueOptions techniqueOptions(glm::ivec2 imageSize) const;

  // {"version": 1, ...}; fromJson validates and names what it rejects.
  nlohmann::json toJson() const;
  static Settings fromJson(const nlohmann::json& state);
};

inline constexpr int kSettingsVersion = 1;

// "composite", "mip", "minip", "average" (InputError otherwise).
RenderMode parseRenderMode(const std::string& text);
std::string renderModeName(RenderMode mode);

}  // namespace tessera::session
