// tessera convert IN OUT [--crop ...] [--downsample ...]
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>

#include "cli/Commands.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/io/FormatRegistry.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/io/VolumeWriter.h"
#include "tessera/io/ZarrStore.h"
#include "tessera/io/ZarrWriter.h"
#include "tessera/session/Convert.h"

namespace tessera::app {

namespace {

struct ConvertOptions {
  std::string in;
  std::string out;
  std::string series;  // DICOM Series Instance UID
  int time = 0;        // OME-Zarr input: time point and channel
  int channel = 0;
  session::ConvertRequest request;  // crop, downsample and the OME-Zarr output's options
  bool quiet = false;
};

// One line on stderr per stage, redrawn in place on a terminal:
// "convert [####------] 40%  writing out.nii.gz  1.2 s".
class Progress {
 public:
  explicit Progress(bool enabled) : enabled_(enabled), tty_(::isatty(2) != 0) {}
  void stage(const std::string& what, double fraction) {
    if (!enabled_) return;
    const int filled = static_cast<int>(fraction * 20.0 + 0.5);
    std::string bar(static_cast<std::size_t>(filled), '#');
    bar.resize(20, '-');
    const double s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    std::fprintf(stderr, "%sconvert [%s] %3d%%  %-40s %6.1f s%s", tty_ ? "\r" : "", bar.c_str(),
                 static_cast<int>(fraction * 100.0 + 0.5), what.c_str(), s, tty_ ? "" : "\n");
    std::fflush(stderr);
  }
  void done() {
    if (enabled_ && tty_) std::fprintf(stderr, "\n");
  }

 private:
  bool enabled_;
  bool tty_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

std::string dimsText(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

OmeZarrWriteOptions zarrOptions(const ConvertOptions& o, Progress& progress) {
  OmeZarrWriteOptions z = session::zarrWriteOptions(o.request);
  z.progress = [&progress](double f, const std::string& what) {
    progress.stage("writing " + what, 0.05 + 0.95 * f);
  };
  return z;
}

void printZarrResult(const ConvertOptions& o, const Volume& shape, const OmeZarrWriteResult& r) {
  std::printf("%s: %s %s -> %s: OME-Zarr (NGFF %s on Zarr v%d%s), %zu levels (", o.in.c_str(),
              dimsText(shape.dims()).c_str(), std::string(scalarTypeName(shape.type())).c_str(),
              o.out.c_str(), o.request.zarrFormat == 3 ? "0.5" : "0.4", o.request.zarrFormat,
              o.request.shard > 0
                  ? (", " + std::to_string(o.request.shard) + "^3 chunks per shard").c_str()
                  : "",
              r.levelDims.size());
  if (o.request.pyramidFactors != "2,2,2") {
    std::printf("factors %s (z,y,x): ", o.request.pyramidFactors.c_str());
  }
  for (std::size_t l = 0; l < r.levelDims.size(); ++l) {
    std::printf("%s%s", l ? ", " : "", dimsText(r.levelDims[l]).c_str());
  }
  std::printf("), chunks %s %s: %llu written, %llu all-zero skipped, %s\n",
              (o.request.chunk.find(',') == std::string::npos ? o.request.chunk + "^3"
                                                              : o.request.chunk + " (z,y,x)")
                  .c_str(),
              o.request.compressor.c_str(), static_cast<unsigned long long>(r.chunksWritten),
              static_cast<unsigned long long>(r.chunksSkipped),
              formatBytes(r.bytesWritten).c_str());
  for (const std::string& note : writeLossNotes(shape, o.out)) {
    std::fprintf(stderr, "note: %s\n", note.c_str());
  }
}

// OME-Zarr to OME-Zarr streams: level 0 of the input is read one slab at a
// time, so memory stays at a few slabs whatever the volume's size.
bool convertStoreStreaming(const ConvertOptions& o, const OmeZarrWriteOptions& zarr,
                           Progress& progress) {
  if (!isZarrStore(o.in) || !o.request.crop.empty() || !o.request.downsample.empty() ||
      !isOmeZarrName(o.out)) {
    return false;
  }
  const ZarrStore in(openZarrStorage(o.in), {.time = o.time, .channel = o.channel});
  const glm::ivec3 d = in.level(0).dims;
  progress.stage("streaming " + dimsText(d) + " from " + o.in, 0.05);
  const OmeZarrWriteResult r = writeOmeZarr(
      in.shape(),
      [&](int z0, int z1) {
        return in.readBox(0, {0, 0, z0}, {d.x, d.y, z1});
      },
      o.out, zarr);
  progress.stage("done", 1.0);
  progress.done();
  printZarrResult(o, in.shape(), r);
  return true;
}

void runConvert(const ConvertOptions& o) {
  Progress progress(!o.quiet);
  // Checked before anything is read, so that a typo fails at once.
  const OmeZarrWriteOptions zarr = zarrOptions(o, progress);
  if (convertStoreStreaming(o, zarr, progress)) return;
  progress.stage("reading " + o.in, 0.0);
  Volume v = readVolume(o.in, {.dicomSeries = o.series, .time = o.time, .channel = o.channel});
  const glm::ivec3 inDims = v.dims();
  progress.stage("read " + dimsText(inDims), 0.4);
  if (!o.request.crop.empty() || !o.request.downsample.empty()) {
    v = session::cropAndDownsample(std::move(v), o.request);
    progress.stage("cropped/downsampled to " + dimsText(v.dims()), 0.6);
  }
  if (isOmeZarrName(o.out)) {
    // The input is in memory already; the pyramid is still built slab by slab.
    const OmeZarrWriteResult r = writeOmeZarr(v, o.out, zarr);
    progress.stage("done", 1.0);
    progress.done();
    printZarrResult(o, v, r);
    return;
  }
  progress.stage("writing " + o.out, 0.7);
  writeVolume(v, o.out);
  progress.stage("done", 1.0);
  progress.done();
  std::printf("%s: %s %s -> %s: %s %s, %s (%s)\n", o.in.c_str(), dimsText(inDims).c_str(),
              std::string(scalarTypeName(v.type())).c_str(), o.out.c_str(),
              dimsText(v.dims()).c_str(), std::string(scalarTypeName(v.type())).c_str(),
              orientationOf(v.direction()).describe().c_str(), formatBytes(v.byteSize()).c_str());
  // What the output format could not hold is said even with --quiet: a
  // silently lost orientation is how left and right get swapped.
  for (const std::string& note : writeLossNotes(v, o.out)) {
    std::fprintf(stderr, "note: %s\n", note.c_str());
  }
}

}  // namespace

void addConvertCommand(CLI::App& app) {
  auto o = std::make_shared<ConvertOptions>();
  CLI::App* cmd = app.add_subcommand(
      "convert",
      "Convert between volume formats (by extension), optionally cropping and downsampling.\n"
      "Output: " +
          writeExtensionsText() +
          "\n(OME-Zarr: NGFF 0.4 on Zarr v2, or 0.5 on v3 with --zarr-format 3, a pyramid of "
          "2x2x2 means (--pyramid-factors 1,2,2: 1x2x2, z kept) down to one chunk,\n"
          "written slab by slab; OME-Zarr input is streamed too, other inputs are read whole).\n"
          "The output appears only when complete (temporary file or folder + rename).\n"
          "`tessera formats` lists what each format keeps and loses.");
  cmd->add_option("in", o->in, "Input volume: " + readExtensionsText())->required();
  cmd->add_option("out", o->out, "Output file (format from its extension)")->required();
  addSeriesOption(cmd, o->series);
  cmd->add_option("--crop", o->request.crop, "Keep voxels x0:x1,y0:y1,z0:z1 (end exclusive)");
  cmd->add_option("--downsample", o->request.downsample, "Box-filter by N or AxBxC");
  addTimeChannelOptions(cmd, o->time, o->channel);
  cmd->add_option("--chunk", o->request.chunk,
                  "OME-Zarr output: chunk edge, 64 or 128 voxels, or Z,Y,X per axis (even, "
                  "8..1024; e.g. 32,512,512)")
      ->default_val("64");
  cmd->add_option("--levels", o->request.levels,
                  "OME-Zarr output: pyramid levels, N or auto (halve until one chunk holds the "
                  "level)")
      ->default_val("auto");
  cmd->add_option("--compressor", o->request.compressor,
                  "OME-Zarr output: zstd (level 3), blosc (lz4 + byte shuffle), zlib or none")
      ->default_val("zstd");
  cmd->add_option("--zarr-format", o->request.zarrFormat,
                  "OME-Zarr output: 2 (NGFF 0.4 on Zarr v2) or 3 (NGFF 0.5 on Zarr v3)")
      ->default_val(2);
  cmd->add_option("--shard", o->request.shard,
                  "OME-Zarr output with --zarr-format 3: N chunks per shard edge "
                  "(sharding_indexed; 0 = unsharded)")
      ->default_val(0);
  cmd->add_option("--pyramid-factors", o->request.pyramidFactors,
                  "OME-Zarr output: each level's factor per axis against the one before, Z,Y,X, "
                  "each 2 (halved) or 1 (kept); 1,2,2 keeps z, as microscopy pyramids do")
      ->default_val("2,2,2");
  cmd->add_flag("--quiet", o->quiet, "No progress on stderr");
  cmd->callback([o] { runConvert(*o); });
}

}  // namespace tessera::app
