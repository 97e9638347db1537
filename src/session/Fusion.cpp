#include "tessera/session/Fusion.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include <glm/common.hpp>
#include <glm/vector_relational.hpp>

#include "tessera/core/Error.h"
#include "tessera/io/VolumeReader.h"

namespace tessera::session {

namespace {

void checkOptions(const OverlayOptions& o) {
  if (!(o.opacity > 0.0 && o.opacity <= 1.0)) {
    throw InputError("--overlay-opacity " + std::to_string(o.opacity) + ": expected (0, 1]");
  }
  if (o.window && !(o.window->max > o.window->min)) {
    throw InputError("--overlay-window " + std::to_string(o.window->min) + " " +
                     std::to_string(o.window->max) + ": expected LO < HI");
  }
  if (!o.labelTable.empty() && !o.labels) {
    throw InputError("a label table needs a label overlay (--overlay-labels)");
  }
}

std::string describeMm(glm::dvec3 p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.1f, %.1f, %.1f) mm", p.x, p.y, p.z);
  return buf;
}

// The world box of a volume's voxel cells, for the no-overlap note.
std::string worldBox(const Volume& v) {
  glm::dvec3 lo(1e300), hi(-1e300);
  for (int c = 0; c < 8; ++c) {
    const glm::dvec3 i(c & 1 ? v.dims().x - 0.5 : -0.5, c & 2 ? v.dims().y - 0.5 : -0.5,
                       c & 4 ? v.dims().z - 0.5 : -0.5);
    const glm::dvec3 w = v.worldOf(i);
    lo = glm::min(lo, w);
    hi = glm::max(hi, w);
  }
  return describeMm(lo) + " .. " + describeMm(hi);
}

}  // namespace

TransferFunction overlayTransferFunction(const std::string& spec) {
  if (spec != "hot") return TransferFunction::fromPresetOrFile(spec);
  // The usual statistical-map / PET colour map; low values transparent so
  // that the anatomy shows through.
  return TransferFunction::fromPoints("hot",
                                      {{0.0, {0.0, 0.0, 0.0}},
                                       {0.35, {1.0, 0.0, 0.0}},
                                       {0.7, {1.0, 1.0, 0.0}},
                                       {1.0, {1.0, 1.0, 1.0}}},
                                      {{0.0, 0.0}, {0.1, 0.0}, {1.0, 1.0}});
}

namespace {

// The label table of `options`: a file, text handed over, or the palette of
// the labels present.
render::LabelTable labelTableOf(const OverlayOptions& options, const Volume& volume) {
  if (!options.labelTable.empty()) return render::LabelTable::load(options.labelTable);
  if (options.labelTableText.empty()) return render::LabelTable::defaultFor(volume);
  const std::string& text = options.labelTableText;
  const std::string name = options.labelTableName.empty() ? "label table" : options.labelTableName;
  const auto first = text.find_first_not_of(" \t\r\n");
  const bool json = first != std::string::npos && text[first] == '{';
  return json ? render::LabelTable::fromJson(text, name) : render::LabelTable::fromText(text, name);
}

// The look of `options` (and of `table` for labels) over a prepared volume.
Overlay lookOf(std::shared_ptr<const Volume> volume, const std::string& name,
               const OverlayOptions& options, render::LabelTable table, const Volume& anatomy) {
  Overlay o;
  o.name = name;
  o.options = options;
  auto fused = std::make_shared<FusedVolume>();
  fused->labels = options.labels;
  fused->opacity = options.opacity;
  if (options.labels) {
    o.labels = std::move(table);
    fused->tf = o.labels.toTransferFunction();
    fused->window = {0.0, 255.0};
  } else {
    fused->tf = overlayTransferFunction(options.tf);
    fused->window = options.window ? *options.window : volume->valueRange();
    if (!(fused->window.width() > 0.0)) fused->window.max = fused->window.min + 1.0;
  }
  if (!fusedOverlaps(anatomy, *volume)) {
    o.note = "the overlay " + name + " (" + worldBox(*volume) + ") does not overlap the anatomy (" +
             worldBox(anatomy) + ") in world space: nothing of it is shown";
  }
  fused->volume = std::move(volume);
  o.fused = std::move(fused);
  return o;
}

void prepareLabels(Volume& volume, const std::string& name) {
  try {
    render::prepareLabelVolume(volume);
  } catch (const InputError& e) {
    throw InputError("--overlay-labels: " + name + " is not a label volume: " + e.what());
  }
}

}  // namespace

Overlay makeOverlay(std::shared_ptr<Volume> volume, const std::string& name,
                    const OverlayOptions& options, const Volume& anatomy) {
  checkOptions(options);
  render::LabelTable table;
  if (options.labels) {
    prepareLabels(*volume, name);
    table = labelTableOf(options, *volume);
  }
  return lookOf(std::move(volume), name, options, std::move(table), anatomy);
}

Overlay restyleOverlay(const Overlay& current, const OverlayOptions& options,
                       const Volume& anatomy) {
  if (!current.fused || !current.fused->volume) throw InputError("no overlay to restyle");
  checkOptions(options);
  std::shared_ptr<const Volume> volume = current.fused->volume;
  if (!options.labels) return lookOf(volume, current.name, options, {}, anatomy);
  if (!current.fused->labels) {  // prepared as labels now, on a copy
    auto copy = std::make_shared<Volume>(*volume);
    prepareLabels(*copy, current.name);
    volume = std::move(copy);
  }
  const OverlayOptions& was = current.options;
  const bool sameTable =
      current.fused->labels && options.labelTable == was.labelTable &&
      (options.labelTableText.empty() || options.labelTableText == was.labelTableText) &&
      options.labelTableName == was.labelTableName;
  OverlayOptions kept = options;
  if (sameTable) kept.labelTableText = was.labelTableText;
  render::LabelTable table = sameTable ? current.labels : labelTableOf(options, *volume);
  return lookOf(std::move(volume), current.name, kept, std::move(table), anatomy);
}

Overlay openOverlay(const std::string& spec, const OverlayOptions& options, const Volume& anatomy) {
  checkOptions(options);
  std::shared_ptr<Volume> volume;
  try {
    volume = std::make_shared<Volume>(readVolume(spec));
  } catch (const InputError& e) {
    throw InputError("--overlay " + std::string(e.what()));
  }
  return makeOverlay(std::move(volume), spec, options, anatomy);
}

namespace {

// The voxel of `shape` a position lies in.
glm::ivec3 voxelOf(const ProbeResult& r) {
  return glm::ivec3(glm::floor(r.anatomyIndex + 0.5));
}

// The probe but the anatomy's value: positions in `shape` (its voxels are
// not read) and the overlay's reading.
ProbeResult probeShape(const Volume& shape, const Overlay* overlay, glm::dvec3 worldMm) {
  ProbeResult r;
  r.worldMm = worldMm;
  r.anatomyIndex = indexOfWorld(shape, worldMm);
  const glm::ivec3 i = voxelOf(r);
  r.inAnatomy =
      glm::all(glm::greaterThanEqual(i, glm::ivec3(0))) && glm::all(glm::lessThan(i, shape.dims()));
  if (!overlay || !overlay->fused) return r;
  const FusedVolume& f = *overlay->fused;
  r.hasOverlay = true;
  r.overlayIndex = indexOfWorld(*f.volume, worldMm);
  const double v = fusedValueAtWorld(f, worldMm);
  r.inOverlay = !std::isnan(v);
  if (!r.inOverlay) return r;
  r.overlayValue = v;
  if (f.labels) {
    r.label = static_cast<int>(std::lround(v));
    const auto it = overlay->labels.labels.find(r.label);
    if (it != overlay->labels.labels.end()) r.labelName = it->second.name;
  }
  return r;
}

}  // namespace

ProbeResult probe(const Volume& anatomy, const Overlay* overlay, glm::dvec3 worldMm) {
  ProbeResult r = probeShape(anatomy, overlay, worldMm);
  const glm::ivec3 i = voxelOf(r);
  if (r.inAnatomy) r.anatomyValue = anatomy.finiteValueAtIndex(anatomy.index(i.x, i.y, i.z));
  return r;
}

ProbeResult probe(const lod::MultiresSource& anatomy, const Overlay* overlay, glm::dvec3 worldMm) {
  const Volume& shape = anatomy.shape();
  ProbeResult r = probeShape(shape, overlay, worldMm);
  if (!r.inAnatomy) return r;
  const glm::ivec3 i = voxelOf(r);
  lod::VoxelBox box{i, i + 1};
  int level = 0;
  if (!anatomy.prefetch(0, box)) {
    // The coarsest level's voxel holding the same point (levels need not halve).
    level = anatomy.levelCount() - 1;
    const glm::ivec3 dl = anatomy.levelInfo(level).dims;
    const glm::ivec3 c =
        glm::clamp(glm::ivec3((glm::dvec3(i) + 0.5) * glm::dvec3(dl) / glm::dvec3(shape.dims())),
                   glm::ivec3(0), dl - 1);
    box = {c, c + 1};
  }
  r.anatomyValue = anatomy.readBox(level, box).finiteValueAtIndex(0);
  return r;
}

std::string probeOverlayText(const ProbeResult& r) {
  if (!r.inOverlay) return "outside";
  char value[48];
  std::snprintf(value, sizeof value, "%g", r.overlayValue);
  if (r.label < 0) return value;
  if (r.label == 0) return "0 (background)";
  return std::to_string(r.label) + " " + (r.labelName.empty() ? "(unnamed)" : r.labelName);
}

glm::dvec3 parseWorldPosition(const std::string& text, const std::string& what) {
  std::istringstream in(text);
  glm::dvec3 p(0.0);
  char c1 = 0, c2 = 0;
  if (!(in >> p.x >> c1 >> p.y >> c2 >> p.z) || c1 != ',' || c2 != ',' || !in.eof() ||
      !std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
    throw InputError(what + " '" + text +
                     "': expected X,Y,Z in millimetres (RAS+), e.g. 40,-20,50");
  }
  return p;
}

}  // namespace tessera::session
