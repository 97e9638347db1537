#pragma once
// A second volume over the session's anatomy (docs/fusion.md): how the CLI,
// the viewers and embedders ask for one (OverlayOptions), how it is opened
// and checked against the anatomy (openFusedVolume), and what the crosshair
// reads at a world position (ProbeResult, Session::probe).
#include <memory>
#include <optional>
#include <string>

#include <glm/vec3.hpp>
#include <nlohmann/json_fwd.hpp>

#include "tessera/core/Image.h"
#include "tessera/core/SliceImage.h"
#include "tessera/core/Volume.h"
#include "tessera/lod/MultiresSource.h"
#include "tessera/reference/FusedVolume.h"
#include "tessera/render/LabelTable.h"

namespace tessera::session {

struct OverlayOptions {
  // Labels: a label table file (LabelTable::load), or "" with `labels` for
  // the default palette; otherwise `tf` (a preset, "hot", or FILE.json).
  bool labels = false;
  std::string labelTable;
  std::string tf = "hot";
  double opacity = 0.5;              // (0, 1]
  std::optional<ValueRange> window;  // raw values; default: the value range (labels: 0..255)
  // A label table handed over as text (a page's or a widget's file: JSON, or
  // the text forms LabelTable::fromText reads), named `labelTableName`;
  // used when `labelTable` (a path) is empty.
  std::string labelTableText;
  std::string labelTableName;
};

// An opened fused volume and what names its labels.
struct Overlay {
  std::shared_ptr<const FusedVolume> fused;
  render::LabelTable labels;  // empty unless fused->labels
  std::string name;           // the file
  std::string note;           // non-empty: e.g. the volumes do not overlap in world space
  OverlayOptions options;     // what it was opened with (the session's state saves them)
};

// Reads `spec` and makes its look. InputError naming the file and option:
// unreadable file, --overlay-labels on a volume that is not one (values
// outside 0..255 or not integers), an unreadable table, an opacity outside
// (0, 1], a reversed window. A fused volume whose box does not meet the
// anatomy's in world space is accepted with a note.
Overlay openOverlay(const std::string& spec, const OverlayOptions& options, const Volume& anatomy);

// The look of `options` for a fused volume already in memory.
Overlay makeOverlay(std::shared_ptr<Volume> volume, const std::string& name,
                    const OverlayOptions& options, const Volume& anatomy);

// The same fused volume (not read again) with another look: labels or a
// colour map, table, opacity, window. A table named as the current one's is
// kept (a page's table text is not in the state).
Overlay restyleOverlay(const Overlay& current, const OverlayOptions& options,
                       const Volume& anatomy);

// The overlay as the session's state holds it (Session::state()): null
// without one, else {"file", "labels", "label_table", "tf", "alpha",
// "window": [lo, hi] or null}.
nlohmann::json overlayState(const Overlay* overlay);
// The options of a saved overlay and its file; InputError naming the key.
OverlayOptions overlayOptionsFromState(const nlohmann::json& state, std::string& file);

// The fused TF for a name: "hot" (black -> red -> yellow -> white, opacity
// rising from 0), or a preset or file (TransferFunction::fromPresetOrFile).
TransferFunction overlayTransferFunction(const std::string& spec);

// The overlay in a slice view: `image` is sliceImage(anatomy, frame, index,
// ...) (the slice views' pixels of the anatomy's voxels; `anatomy` gives the
// shape and index -> world affine, its voxels are not read). Each pixel's
// voxel centre is looked up in the fused volume by world position and its
// colour mixed in by its weight w (the fusion rule's colour, docs/fusion.md);
// outside the fused volume's box the pixel stays.
void fuseSliceImage(Image& image, const Volume& anatomy, const SliceFrame& frame, int index,
                    const Overlay& overlay);
// The same in a slice view of a pyramid's level (a store's slices, read at
// the finest level a view needs): `image` is viewer::SliceGeometry(level's
// dims and spacing, the shape's direction, frame.axis).render(anatomy,
// level, index, ...). Every level spans level 0's box, so a level voxel's
// centre is placed in world space by the shape's (level 0's) affine; the
// fused volume is resampled there as for a volume in memory. InputError for
// a level or index outside the pyramid, or an image of another size.
void fuseSliceImage(Image& image, const lod::MultiresSource& anatomy, int level,
                    const SliceFrame& frame, int index, const Overlay& overlay);

// What the crosshair reads at a world position (RAS+ mm).
struct ProbeResult {
  glm::dvec3 worldMm{0.0};
  glm::dvec3 anatomyIndex{0.0};  // continuous voxel index
  bool inAnatomy = false;
  double anatomyValue = 0.0;  // the voxel the position lies in
  bool hasOverlay = false;
  bool inOverlay = false;
  glm::dvec3 overlayIndex{0.0};
  double overlayValue = 0.0;  // labels: the nearest voxel; otherwise trilinear
  int label = -1;             // labels: the label value (0: background)
  std::string labelName;      // its name in the table ("" for 0 or an unnamed label)
};

// The probe of `anatomy` (in memory) and, when given, `overlay` at worldMm.
ProbeResult probe(const Volume& anatomy, const Overlay* overlay, glm::dvec3 worldMm);
// The same over a pyramid (a store, streamed or drawn by the page): the
// position in its shape (level 0), the value of level 0's voxel when its
// chunk is at hand (MultiresSource::prefetch), else of the coarsest level's.
ProbeResult probe(const lod::MultiresSource& anatomy, const Overlay* overlay, glm::dvec3 worldMm);

// The overlay's part of a probe as the readouts show it: "58 Postcentral_R",
// "0 (background)", "3.25", or "outside".
std::string probeOverlayText(const ProbeResult& r);

// The probe as JSON (`tessera probe --json`, the viewers' readouts):
// {"world_mm", "anatomy": {"index", "inside", "value"}, "overlay": {"index",
// "inside", "value", "label", "label_name"}, "overlay_text"}; no "overlay"
// without one.
nlohmann::json probeJson(const ProbeResult& r);

// "X,Y,Z" in mm; InputError naming `what` otherwise.
glm::dvec3 parseWorldPosition(const std::string& text, const std::string& what);

}  // namespace tessera::session
