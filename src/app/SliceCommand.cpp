// tessera slice FILE|STORE --axis x|y|z --index K --out PNG (issue 15 item 5):
// one index-axis slice at native voxel resolution (nearest voxel, no
// interpolation), read as a one-voxel-thick box of one pyramid level, shown
// in the radiological convention with the patient directions of its edges.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "app/Commands.h"
#include "app/VolumePyramid.h"
#include "tessera/core/Error.h"
#include "tessera/core/Image.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/core/TransferFunction.h"

namespace tessera::app {

namespace {

struct SliceOptions {
  std::string file;
  std::string series;
  int time = 0;
  int channel = 0;
  std::string axis;
  int index = -1;
  std::vector<double> window;
  std::string level = "native";
  std::string tf = "grey";
  std::string out = "slice.png";
  bool json = false;
};

int parseAxis(const std::string& text) {
  if (text == "x" || text == "i") return 0;
  if (text == "y" || text == "j") return 1;
  if (text == "z" || text == "k") return 2;
  throw InputError("--axis '" + text + "': expected x, y or z (an index axis of the volume)");
}

// How the slice's two in-plane index axes land on the image. Radiological
// convention, whatever the storage order: axial and coronal slices have
// the patient's left on the image's right (as if facing the patient; axial
// seen from the feet), anterior up (axial) or superior up (coronal);
// sagittal slices have anterior on the image's left and superior up.
struct SliceFrame {
  std::string plane;         // axial, coronal or sagittal (by the normal's nearest world axis)
  int colAxis = 0;           // index axis along image columns (left to right)
  int rowAxis = 1;           // index axis along image rows (top to bottom)
  bool colReversed = false;  // column 0 shows the last voxel of colAxis
  bool rowReversed = false;  // row 0 shows the last voxel of rowAxis
  std::string left, right, top, bottom;  // patient directions of the edges
};

SliceFrame sliceFrame(const glm::dmat3& direction, int axis) {
  const glm::dmat3 frame = nearestOrthonormal(direction);
  const glm::dvec3 normal = frame[axis];
  int dominant = 0;
  for (int w = 1; w < 3; ++w) {
    if (std::abs(normal[w]) > std::abs(normal[dominant])) dominant = w;
  }
  SliceFrame f;
  glm::dvec3 screenRight, screenUp;  // world (RAS) directions of image right and up
  if (dominant == 2) {
    f.plane = "axial";
    screenRight = {-1, 0, 0};
    screenUp = {0, 1, 0};
  } else if (dominant == 1) {
    f.plane = "coronal";
    screenRight = {-1, 0, 0};
    screenUp = {0, 0, 1};
  } else {
    f.plane = "sagittal";
    screenRight = {0, -1, 0};
    screenUp = {0, 0, 1};
  }
  const int p = (axis + 1) % 3, q = (axis + 2) % 3;
  const bool pHorizontal =
      std::abs(glm::dot(frame[p], screenRight)) >= std::abs(glm::dot(frame[q], screenRight));
  f.colAxis = pHorizontal ? p : q;
  f.rowAxis = pHorizontal ? q : p;
  f.colReversed = glm::dot(frame[f.colAxis], screenRight) < 0.0;
  // Rows grow downwards: the index grows downwards unless it points up.
  f.rowReversed = glm::dot(frame[f.rowAxis], screenUp) > 0.0;
  const glm::dvec3 right = frame[f.colAxis] * (f.colReversed ? -1.0 : 1.0);
  const glm::dvec3 down = frame[f.rowAxis] * (f.rowReversed ? -1.0 : 1.0);
  f.right = directionLabel(right);
  f.left = directionLabel(-right);
  f.bottom = directionLabel(down);
  f.top = directionLabel(-down);
  return f;
}

// Pixel -> voxel along one image axis: pixels of `pixelMm` over `n` voxels
// of `spacing`, nearest voxel centre, optionally reversed.
int voxelOf(int pixel, double pixelMm, double spacing, int n, bool reversed) {
  const int t =
      std::clamp(static_cast<int>(std::floor((pixel + 0.5) * pixelMm / spacing)), 0, n - 1);
  return reversed ? n - 1 - t : t;
}

void runSliceCommand(const SliceOptions& o) {
  const int axis = parseAxis(o.axis);
  const TransferFunction tf = TransferFunction::fromPresetOrFile(o.tf);
  const std::string spec = o.file.empty() ? defaultVolumeSpec() : o.file;
  const VolumePyramid pyramid =
      openVolumePyramid(spec, {.series = o.series, .time = o.time, .channel = o.channel});
  const lod::MultiresSource& source = *pyramid.source;
  const int level = parseLevel(o.level, source.levelCount(), spec);
  const lod::LevelInfo info = source.levelInfo(level);
  const char* axisName = "xyz";
  if (o.index < 0 || o.index >= info.dims[axis]) {
    throw InputError("--index " + std::to_string(o.index) + " is outside 0.." +
                     std::to_string(info.dims[axis] - 1) + " for axis " + axisName[axis] + " of " +
                     spec + " level " + std::to_string(level) + " (" + std::to_string(info.dims.x) +
                     "x" + std::to_string(info.dims.y) + "x" + std::to_string(info.dims.z) + ")");
  }
  lod::VoxelBox box{glm::ivec3(0), info.dims};
  box.begin[axis] = o.index;
  box.end[axis] = o.index + 1;
  const Volume slab = source.readBox(level, box);

  ValueRange window = source.shape().window();
  if (!o.window.empty()) {
    if (o.window.size() != 2 || !(o.window[1] > o.window[0])) {
      throw InputError("--window takes two numbers MIN MAX with MAX > MIN");
    }
    window = {o.window[0], o.window[1]};
  }
  const SliceFrame f = sliceFrame(source.shape().direction(), axis);
  const glm::dvec3 spacing = slab.spacing();
  const double pixelMm = std::min(spacing[f.colAxis], spacing[f.rowAxis]);
  const int nc = info.dims[f.colAxis], nr = info.dims[f.rowAxis];
  const int width = std::max(1, static_cast<int>(std::lround(nc * spacing[f.colAxis] / pixelMm)));
  const int height = std::max(1, static_cast<int>(std::lround(nr * spacing[f.rowAxis] / pixelMm)));
  Image image(width, height);
  const bool grey = o.tf == "grey";
  for (int row = 0; row < height; ++row) {
    const int vr = voxelOf(row, pixelMm, spacing[f.rowAxis], nr, f.rowReversed);
    for (int col = 0; col < width; ++col) {
      glm::ivec3 v(0);
      v[f.colAxis] = voxelOf(col, pixelMm, spacing[f.colAxis], nc, f.colReversed);
      v[f.rowAxis] = vr;
      const double value = slab.finiteValueAtIndex(slab.index(v.x, v.y, v.z));
      const double n = window.max > window.min
                           ? std::clamp((value - window.min) / (window.max - window.min), 0.0, 1.0)
                           : 0.0;
      const glm::dvec3 rgb = grey ? glm::dvec3(n) : tf.color(n);
      std::uint8_t* px = image.pixel(col, row);
      for (int c = 0; c < 3; ++c) {
        px[c] = static_cast<std::uint8_t>(std::lround(std::clamp(rgb[c], 0.0, 1.0) * 255.0));
      }
      px[3] = 255;
    }
  }
  image.writePng(o.out);

  nlohmann::json j;
  j["file"] = spec;
  j["out"] = o.out;
  j["axis"] = std::string(1, axisName[axis]);
  j["index"] = o.index;
  j["level"] = level;
  j["level_dims"] = {info.dims.x, info.dims.y, info.dims.z};
  j["plane"] = f.plane;
  j["convention"] =
      "radiological: axial/coronal patient left on image right, sagittal anterior on image left";
  j["orientation"] = orientationOf(source.shape().direction()).describe();
  j["edges"] = {{"left", f.left}, {"right", f.right}, {"top", f.top}, {"bottom", f.bottom}};
  j["columns"] = {{"axis", std::string(1, axisName[f.colAxis])}, {"reversed", f.colReversed}};
  j["rows"] = {{"axis", std::string(1, axisName[f.rowAxis])}, {"reversed", f.rowReversed}};
  j["width"] = width;
  j["height"] = height;
  j["pixel_mm"] = pixelMm;
  j["window"] = {window.min, window.max};
  j["tf"] = grey ? "grey" : tf.name;
  j["voxels_read"] = box.count();
  j["level_voxels"] = lod::VoxelBox{glm::ivec3(0), info.dims}.count();
  if (pyramid.storage) {
    j["chunks_read"] = pyramid.storage->chunksRead();
    j["chunk_bytes_read"] = pyramid.storage->chunkBytesRead();
    j["chunks_touched"] = chunksTouched(box, info.chunk, info.dims);
    j["chunks_in_level"] =
        chunksTouched(lod::VoxelBox{glm::ivec3(0), info.dims}, info.chunk, info.dims);
  }
  if (o.json) {
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf("wrote %s (%dx%d, %.4g mm pixels): %s slice %c=%d of %s level %d\n", o.out.c_str(),
              width, height, pixelMm, f.plane.c_str(), axisName[axis], o.index, spec.c_str(),
              level);
  std::printf(
      "edges    left %s, right %s, top %s, bottom %s (radiological: patient left on "
      "the image's right; sagittal: anterior left)\n",
      f.left.c_str(), f.right.c_str(), f.top.c_str(), f.bottom.c_str());
  if (pyramid.storage) {
    std::printf("read     %llu chunks (%llu bytes) of %llu in the level\n",
                static_cast<unsigned long long>(pyramid.storage->chunksRead()),
                static_cast<unsigned long long>(pyramid.storage->chunkBytesRead()),
                static_cast<unsigned long long>(j["chunks_in_level"].get<std::uint64_t>()));
  }
}

}  // namespace

void addSliceCommand(CLI::App& app) {
  auto o = std::make_shared<SliceOptions>();
  CLI::App* cmd = app.add_subcommand(
      "slice",
      "Write one 2D slice along an index axis at native voxel resolution (nearest voxel) to a "
      "PNG, read as a one-voxel-thick box (a store reads only the chunks it touches). "
      "Radiological convention: axial and coronal slices show the patient's left on the image's "
      "right, sagittal slices anterior on the left, superior (or anterior, axial) up; the "
      "patient directions of the four edges are printed");
  cmd->add_option("file", o->file, kVolumeHelp);
  addSeriesOption(cmd, o->series);
  addTimeChannelOptions(cmd, o->time, o->channel);
  cmd->add_option("--axis", o->axis, "Index axis the slice is normal to: x, y or z")->required();
  cmd->add_option("--index", o->index, "Slice index along --axis (0-based, in the level)")
      ->required();
  cmd->add_option("--window", o->window,
                  "Value window MIN MAX (raw values); default: the volume's window")
      ->expected(2);
  cmd->add_option("--level", o->level, "Pyramid level: native (0, the finest) or N")
      ->capture_default_str();
  cmd->add_option("--tf", o->tf,
                  "grey, or colour by a transfer function (preset or FILE.json; colour only)")
      ->capture_default_str();
  cmd->add_option("--out", o->out, "Output PNG (square pixels of the finer in-plane spacing)")
      ->capture_default_str();
  cmd->add_flag("--json", o->json, "Print one JSON object (edges, mapping, reads)");
  cmd->callback([o] { runSliceCommand(*o); });
}

}  // namespace tessera::app
