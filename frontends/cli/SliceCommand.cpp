// tessera slice FILE|STORE --axis x|y|z --index K --out PNG:
// one index-axis slice at native voxel resolution (nearest voxel, no
// interpolation), read as a one-voxel-thick box of one pyramid level, shown
// in the radiological convention with the patient directions of its edges.
#include <cstdio>

#include <nlohmann/json.hpp>

#include "cli/Commands.h"
#include "tessera/core/Error.h"
#include "tessera/core/Image.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/core/SliceImage.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/session/ModalityDefault.h"
#include "tessera/session/VolumePyramid.h"

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
  const CLI::App* command = nullptr;  // which options the command line gave
};

int parseAxis(const std::string& text) {
  if (text == "x" || text == "i") return 0;
  if (text == "y" || text == "j") return 1;
  if (text == "z" || text == "k") return 2;
  throw InputError("--axis '" + text + "': expected x, y or z (an index axis of the volume)");
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

  // The render's window (session/ModalityDefault.h): a CT's own, else its
  // default preset's HU; a clinical --tf's.
  const bool tfGiven = o.command && o.command->get_option("--tf")->count() > 0;
  ValueRange window =
      session::sliceWindow(source.shape(), slab.hasWindow(), tfGiven ? &tf : nullptr);
  if (!o.window.empty()) {
    if (o.window.size() != 2 || !(o.window[1] > o.window[0])) {
      throw InputError("--window takes two numbers MIN MAX with MAX > MIN");
    }
    window = {o.window[0], o.window[1]};
  }
  // The frame of the whole volume (core/SliceImage.h); the slab is its
  // slice `index`, at index 0 of the slab.
  const SliceFrame f = sliceFrame(source.shape().direction(), axis);
  const glm::dvec3 spacing = slab.spacing();
  const SliceRaster raster = sliceRaster(f, info.dims, spacing);
  const int width = raster.width, height = raster.height;
  const double pixelMm = raster.pixelMm;
  const bool grey = o.tf == "grey";
  const Image image = sliceImage(slab, f, 0, window, grey ? nullptr : &tf);
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
  addVolumeOptions(cmd, o->file, o->series);
  addTimeChannelOptions(cmd, o->time, o->channel);
  cmd->add_option("--axis", o->axis, "Index axis the slice is normal to: x, y or z")->required();
  cmd->add_option("--index", o->index, "Slice index along --axis (0-based, in the level)")
      ->required();
  cmd->add_option("--window", o->window,
                  "Value window MIN MAX (raw values); default: the volume's window")
      ->expected(2);
  addDefaultedOption(cmd, "--level", o->level, "Pyramid level: native (0, the finest) or N");
  addDefaultedOption(cmd, "--tf", o->tf,
                     "grey, or colour by a transfer function (preset or FILE.json; colour only)");
  addDefaultedOption(cmd, "--out", o->out,
                     "Output PNG (square pixels of the finer in-plane spacing)");
  cmd->add_flag("--json", o->json, "Print one JSON object (edges, mapping, reads)");
  o->command = cmd;
  cmd->callback([o] { runSliceCommand(*o); });
}

}  // namespace tessera::app
