#pragma once
// A categorical colour table for label volumes (atlases such as mricron's
// aal and brodmann): per label value a name, colour, opacity and visibility.
// Rendered as a transfer function whose control points sit exactly at the
// label values (window 0..255, a 256-entry table, nearest-neighbour
// sampling: RenderSettings::nearest), so a sample shows its voxel's label
// colour and nothing in between — on every technique and in the reference.
#include <filesystem>
#include <map>
#include <string>

#include <glm/vec3.hpp>

#include "tessera/core/RenderSettings.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/core/Volume.h"

namespace tessera::render {

struct Label {
  std::string name;
  glm::dvec3 color{1.0};
  double opacity = 1.0;
  bool visible = true;
};

class LabelTable {
 public:
  // Label values 1..255 (0 is the background and never drawn).
  std::map<int, Label> labels;

  // The default palette for the labels present in `volume` (colours spread
  // by the golden angle in hue, opacity 1). InputError if the volume is not
  // a label volume this can render: integer values in 0..255.
  static LabelTable defaultFor(const Volume& volume);
  // JSON ({"labels": [{"value": 1, "name": "...", "color": [r, g, b] (0..1),
  // "opacity": 1, "visible": true}, ...]}) or a label text file: ITK-SNAP
  // ("IDX R G B A VIS MSH \"NAME\"", colours 0..255), FreeSurfer
  // ("IDX NAME R G B A") or mricron ("IDX NAME [CODE]": default colours).
  // Labels the volume holds but the file does not name stay hidden.
  // InputError names the file and line of anything it cannot read.
  static LabelTable load(const std::filesystem::path& path);
  static LabelTable fromJson(const std::string& text, const std::string& what);
  static LabelTable fromText(const std::string& text, const std::string& what);

  // The 256-entry categorical transfer function (x = value / 255).
  TransferFunction toTransferFunction() const;
  // The default palette's colour of label `value`.
  static glm::dvec3 paletteColor(int value);
};

// Prepares a label volume for rendering: checks it (u8-representable
// integers), sets its window to 0..255. InputError otherwise.
void prepareLabelVolume(Volume& volume);

// What a label render changes besides the volume and the TF, shared by
// `tessera render --labels` and the viewers: no interpolation across labels
// (RenderSettings::nearest) and one TF table entry per label value.
constexpr int kLabelLutSize = 256;
void applyLabelSettings(RenderSettings& settings);

}  // namespace tessera::render
