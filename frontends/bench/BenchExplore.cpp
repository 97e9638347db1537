#include "bench/BenchExplore.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <numeric>
#include <optional>
#include <sstream>
#include <thread>

#include "cli/Commands.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/core/Timing.h"
#include "tessera/layout/Planner.h"
#include "tessera/lod/GridNavigator.h"
#include "tessera/lod/InCoreVolumeSource.h"
#include "tessera/lod/ProceduralMultiresSource.h"
#include "tessera/session/RenderRun.h"

namespace tessera::app {

namespace {

// The paper's storage: the volume in one 3D texture.
constexpr const char* kPaperLayout = "texture3d";

struct ExploreBenchOptions {
  bool run = false;
  std::string volume = "head:512x512x894";
  std::string profile = "shield-k1";
  std::string size = "512x512";
  int frames = 3;            // per fixed view (median)
  double spinDeg = 30.0;     // the paper spins 5 deg per frame; 30 keeps a CPU run short
  int region = 256;          // bread-slice side
  int gridCells = 4;         // the paper's 4x4x4 split
  double alpha = 0.03;       // per sample, as the paper's alpha
  double stepsAcross = 355;  // the paper's step: 1/355 of the texture cube
  int maxSteps = 500;
  std::string out;
};

ExploreBenchOptions& options() {
  static ExploreBenchOptions o;
  return o;
}

// One way of looking at the volume (a row group of the paper's tables).
struct Subject {
  std::string name;
  std::string what;  // dims and where from
  std::shared_ptr<Volume> volume;
  std::string skipped;  // why it was not rendered (does not fit the profile)
};

// Reads `box` of `level` in z slabs on all cores (the generated field costs
// a few hundred ns per voxel) into one volume.
Volume readParallel(const lod::MultiresSource& source, int level, const lod::VoxelBox& box) {
  const glm::ivec3 s = box.size();
  const int threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  std::vector<Volume> slabs(static_cast<std::size_t>(threads));
  std::vector<std::thread> workers;
  std::vector<std::string> errors(static_cast<std::size_t>(threads));
  const int per = (s.z + threads - 1) / threads;
  for (int t = 0; t < threads; ++t) {
    workers.emplace_back([&, t] {
      lod::VoxelBox slab = box;
      slab.begin.z = box.begin.z + t * per;
      slab.end.z = std::min(box.end.z, slab.begin.z + per);
      if (slab.begin.z >= slab.end.z) return;
      try {
        slabs[static_cast<std::size_t>(t)] = source.readBox(level, slab);
      } catch (const std::exception& e) {
        errors[static_cast<std::size_t>(t)] = e.what();
      }
    });
  }
  for (std::thread& w : workers) w.join();
  for (const std::string& e : errors) {
    if (!e.empty()) throw Error(e);
  }
  Volume out = source.readBox(level, {box.begin, box.begin + 1});  // geometry of the first voxel
  Volume whole = Volume::allocate(s, ScalarType::U8, source.describe());
  whole.setSpacing(out.spacing());
  whole.setDirection(out.direction());
  whole.setOrigin(out.origin());
  whole.setWindow(source.shape().window());
  std::uint8_t* dst = whole.dataAs<std::uint8_t>();
  for (const Volume& slab : slabs) {
    if (!slab.hasData()) continue;
    std::memcpy(dst, slab.dataAs<std::uint8_t>(), slab.voxelCount());
    dst += slab.voxelCount();
  }
  whole.invalidateRange();
  return whole;
}

std::string dimsText(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

// The paper's colouring: grey by value, a constant opacity `alpha` per
// sample above `minValue` (normalised), nothing below.
TransferFunction paperTf(double alpha, double minValue, double sampleDistance) {
  TransferFunction tf;
  tf.name = "schultz-alpha";
  tf.addColor(0.0, glm::dvec3(0.0));
  tf.addColor(1.0, glm::dvec3(1.0));
  if (minValue > 0.0) tf.addOpacity(std::max(0.0, minValue - 1e-4), 0.0);
  tf.addOpacity(minValue, alpha);
  tf.addOpacity(1.0, alpha);
  tf.opacityUnitLength = sampleDistance;
  return tf;
}

struct Cell {
  std::string view;  // sagittal, frontal, spin
  double zoom = 1.0;
  double minValue = 0.0;
  double ms = 0.0;
};

struct SubjectResult {
  const Subject* subject = nullptr;
  std::vector<Cell> cells;
  std::uint64_t volumeTextureBytes = 0;
  std::uint64_t textureBytes = 0;
  std::string layout;
};

RenderRequest requestFor(const ExploreBenchOptions& o, const Volume& v, double azimuth, double zoom,
                         int repeat, double rotate) {
  RenderRequest req;
  parseSize(o.size, req.width, req.height);
  req.settings.render = RenderSettings();  // plain sampling, as the paper's runs
  req.settings.layout = kPaperLayout;
  req.settings.camera.azimuthDeg = azimuth;
  req.settings.camera.zoom = zoom;
  req.repeat = repeat;
  req.rotateDeg = rotate;
  // The paper steps 1/stepsAcross of the texture cube: the same number of
  // samples across every subject, whatever its voxel count.
  const glm::dvec3 extent = v.extent();
  const double longest = std::max({extent.x, extent.y, extent.z});
  const glm::dvec3 sp = v.spacing();
  const double minSpacing = std::min({sp.x, sp.y, sp.z});
  req.settings.render.stepVoxels = longest / o.stepsAcross / minSpacing;
  req.settings.render.maxSteps = o.maxSteps;
  return req;
}

// One cell of the table for one subject: a fixed view (median of the
// frames after the first) or a spin (mean over the turn, as the paper).
void benchCell(DeviceSession& device, const ExploreBenchOptions& o, const Subject& s,
               const Cell& cell, SubjectResult& r) {
  const lod::InCoreVolumeSource source(s.volume);
  const bool spin = cell.view == "spin";
  const int spinFrames = std::max(1, static_cast<int>(std::lround(360.0 / o.spinDeg)));
  // Frontal: from anterior (azimuth 0, rays along -y); sagittal: from the
  // patient's right (azimuth 90: the eye on +x, rays along -x).
  const double azimuth = cell.view == "sagittal" ? 90.0 : 0.0;
  RenderRequest req = requestFor(o, *s.volume, azimuth, cell.zoom,
                                 spin ? spinFrames + 1 : o.frames + 1, spin ? o.spinDeg : 0.0);
  const glm::dvec3 sp = s.volume->spacing();
  req.settings.tf = paperTf(o.alpha, cell.minValue,
                            req.settings.render.stepVoxels * std::min({sp.x, sp.y, sp.z}));
  const RenderResult rr = runRender(device, source, req);
  // Frame 0 pays for the first use of the texture: it is left out.
  const std::vector<double> frames(rr.frameMs.begin() + 1, rr.frameMs.end());
  Cell done = cell;
  done.ms =
      spin ? std::accumulate(frames.begin(), frames.end(), 0.0) / frames.size() : median(frames);
  r.cells.push_back(done);
  r.volumeTextureBytes = rr.volumeTextureBytes;
  r.textureBytes = std::max(r.textureBytes, rr.textureBytes);
  r.layout = rr.layout;
  std::fprintf(stderr, "bench explore: %s %s zoom %.1f min %.2f: %.0f ms\n", s.name.c_str(),
               cell.view.c_str(), cell.zoom, cell.minValue, done.ms);
}

// Every cell for every subject, the subjects interleaved cell by cell so
// that the load of a shared machine falls on all of them alike.
std::vector<SubjectResult> benchSubjects(DeviceSession& device, const ExploreBenchOptions& o,
                                         const std::vector<Subject>& subjects) {
  std::vector<Cell> cells;
  for (const char* view : {"sagittal", "frontal"}) {
    for (double zoom : {1.0, 1.5}) {
      for (double minValue : {0.0, 0.84}) cells.push_back({view, zoom, minValue, 0.0});
    }
  }
  for (double zoom : {1.0, 1.5}) cells.push_back({"spin", zoom, 0.0, 0.0});
  std::vector<SubjectResult> results(subjects.size());
  for (const Cell& cell : cells) {
    for (std::size_t i = 0; i < subjects.size(); ++i) {
      results[i].subject = &subjects[i];
      if (subjects[i].skipped.empty()) benchCell(device, o, subjects[i], cell, results[i]);
    }
  }
  return results;
}

double cellMs(const SubjectResult& r, const std::string& view, double zoom, double minValue) {
  for (const Cell& c : r.cells) {
    if (c.view == view && c.zoom == zoom && c.minValue == minValue) return c.ms;
  }
  return -1.0;
}

std::string msCell(double ms) {
  if (ms < 0.0) return "-";
  char t[48];
  std::snprintf(t, sizeof t, "%.0f (%.1f fps)", ms, 1000.0 / ms);
  return t;
}

std::string report(const ExploreBenchOptions& o, const std::vector<Subject>& subjects,
                   const std::vector<SubjectResult>& results, const std::string& renderer) {
  std::ostringstream s;
  int width = 0, height = 0;
  parseSize(o.size, width, height);
  s << "Volume " << o.volume << " (u8, generated), profile " << o.profile << ", GL " << renderer
    << "; ray casting into " << width << "x" << height << ", texture3d, step 1/" << o.stepsAcross
    << " of the longest side (at most " << o.maxSteps << " steps), grey, alpha " << o.alpha
    << " per sample above the min value, early ray "
    << "termination at 0.99. Fixed views: median of " << o.frames
    << " frames after the first; spin: mean over a full turn at " << o.spinDeg
    << " deg per frame; subjects interleaved cell by cell. Frontal: from anterior (rays along y); "
       "sagittal: from the side (rays "
       "along x).\n\n";
  s << "| subject | volume | texture bytes (volume / all) | sagittal z1 | sagittal z1.5 | frontal "
       "z1 | frontal z1.5 | spin z1 | spin z1.5 |\n|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < subjects.size(); ++i) {
    const Subject& sub = subjects[i];
    if (!sub.skipped.empty()) {
      s << "| " << sub.name << " | " << sub.what << " | - | " << sub.skipped << " | | | | | |\n";
      continue;
    }
    const SubjectResult& r = results[i];
    s << "| " << sub.name << " | " << sub.what << " | " << formatBytes(r.volumeTextureBytes)
      << " / " << formatBytes(r.textureBytes);
    for (const char* view : {"sagittal", "frontal", "spin"}) {
      for (double zoom : {1.0, 1.5}) s << " | " << msCell(cellMs(r, view, zoom, 0.0));
    }
    s << " |\n";
  }
  s << "\nms per frame (frames per second); min value 0. With min value 0.84 (fixed views):\n\n"
    << "| subject | sagittal z1 | sagittal z1.5 | frontal z1 | frontal z1.5 |\n"
    << "|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < subjects.size(); ++i) {
    if (!subjects[i].skipped.empty()) continue;
    s << "| " << subjects[i].name;
    for (const char* view : {"sagittal", "frontal"}) {
      for (double zoom : {1.0, 1.5}) s << " | " << msCell(cellMs(results[i], view, zoom, 0.84));
    }
    s << " |\n";
  }
  return s.str();
}

void runExploreBench(const ExploreBenchOptions& o) {
  DeviceSession device = openDevice(o.profile);
  const lod::ProceduralMultiresSource source(o.volume);
  const glm::ivec3 dims = source.levelInfo(0).dims;
  std::vector<Subject> subjects;

  // Full volume, where the profile's limits and budgets hold it in core.
  {
    Subject full{"full", dimsText(dims) + " (level 0)", nullptr, ""};
    layout::PlanRequest pr;
    pr.streamed = false;
    pr.layout = kPaperLayout;
    std::optional<layout::Plan> plan;
    std::string refusal;
    try {
      plan = layout::planLayout(source.shape(), device.limits, pr);
    } catch (const InputError& e) {
      refusal = e.what();
    }
    const std::uint64_t bytes = source.shape().voxelCount();
    if (!plan || plan->downsampled()) {
      full.skipped =
          "does not fit " + o.profile + " in one 3D texture: " + (plan ? plan->reason : refusal);
    } else if (bytes > HostBudget::global().limitBytes()) {
      full.skipped = "over the host budget of " + o.profile;
    } else {
      full.volume = std::make_shared<Volume>(readParallel(source, 0, {glm::ivec3(0), dims}));
    }
    subjects.push_back(std::move(full));
  }
  // The downscaled overview: level 1 (the paper's 256x256x447).
  {
    const glm::ivec3 d1 = source.levelInfo(1).dims;
    subjects.push_back({"overview", dimsText(d1) + " (level 1)",
                        std::make_shared<Volume>(readParallel(source, 1, {glm::ivec3(0), d1})),
                        ""});
  }
  // Grid view: the 2x2x2 block around the centre point of the paper's split.
  {
    const lod::GridNavigator grid = lod::GridNavigator::splitInto(dims, glm::ivec3(o.gridCells));
    const lod::VoxelBox box = grid.blockBox(grid.point());
    subjects.push_back(
        {"grid view (8 cells)",
         dimsText(box.size()) + " = 8 x " + dimsText(grid.cellSize()) + " at level 0",
         std::make_shared<Volume>(readParallel(source, 0, box)), ""});
  }
  // Bread slice: a region^3 box at native resolution around the centre.
  {
    const glm::ivec3 side = glm::min(glm::ivec3(o.region), dims);
    const glm::ivec3 begin = (dims - side) / 2;
    subjects.push_back({"bread slice", dimsText(side) + " at level 0",
                        std::make_shared<Volume>(readParallel(source, 0, {begin, begin + side})),
                        ""});
  }
  const std::vector<SubjectResult> results = benchSubjects(device, o, subjects);
  const std::string table = report(o, subjects, results, device.context->caps().renderer);
  std::printf("%s", table.c_str());
  if (!o.out.empty()) {
    std::ofstream f(o.out);
    if (!f) throw InputError("--explore-out " + o.out + ": cannot write");
    f << table;
  }
}

}  // namespace

void addExploreBenchOptions(CLI::App* cmd) {
  ExploreBenchOptions& o = options();
  cmd->add_flag("--explore", o.run,
                "Schultz 2016 Tables 1-4 on a generated volume: full volume (where the profile "
                "holds it), level-1 overview, grid view block (8 cells of a 4x4x4 split) and a "
                "256^3 bread-slice region at native resolution; sagittal, frontal and spin at "
                "zoom 1 and 1.5: ms per frame and texture bytes");
  addDefaultedOption(cmd, "--explore-volume", o.volume, "With --explore: head:WxHxD");
  addDefaultedOption(cmd, "--explore-profile", o.profile, "With --explore: device profile");
  addDefaultedOption(cmd, "--explore-size", o.size, "With --explore: image size");
  addDefaultedOption(cmd, "--explore-frames", o.frames, "With --explore: frames per fixed view");
  addDefaultedOption(cmd, "--explore-spin", o.spinDeg, "With --explore: degrees per spin frame");
  cmd->add_option("--explore-out", o.out, "With --explore: also write the table to this file");
}

bool runExploreBenchIfAsked() {
  if (!options().run) return false;
  const ExploreBenchOptions& o = options();
  if (o.frames < 1 || !(o.spinDeg > 0.0 && o.spinDeg <= 360.0)) {
    throw InputError("--explore-frames must be >= 1 and --explore-spin in (0, 360]");
  }
  runExploreBench(o);
  return true;
}

}  // namespace tessera::app
