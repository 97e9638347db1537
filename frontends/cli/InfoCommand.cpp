#include <cstdio>
#include <filesystem>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli/Commands.h"
#include "tessera/core/Histogram.h"
#include "tessera/core/HostBudget.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/io/DicomSeriesReader.h"
#include "tessera/io/DicomWeb.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/io/ZarrStore.h"
#include "tessera/session/VolumeInfo.h"

namespace tessera::app {

std::string defaultVolumeSpec() {
  const char* ch2 = "/usr/share/mricron/templates/ch2.nii.gz";
  std::error_code ec;
  if (std::filesystem::exists(ch2, ec)) return ch2;
  return "gen:shepp-logan:128";
}

namespace {
struct InfoOptions {
  std::string file;
  std::string series;
  int time = 0;
  int channel = 0;
  bool json = false;
};

void printZarrLevels(const ZarrStore& store) {
  std::printf("store       %s\n", store.describe().c_str());
  for (int l = 0; l < store.levelCount(); ++l) {
    const ZarrLevel& lv = store.level(l);
    std::printf("level %-5d %d x %d x %d, chunks %d x %d x %d, spacing %g x %g x %g, %s\n", l,
                lv.dims.x, lv.dims.y, lv.dims.z, lv.chunk.x, lv.chunk.y, lv.chunk.z, lv.spacing.x,
                lv.spacing.y, lv.spacing.z, lv.array.compressorText.c_str());
  }
  for (const std::string& n : store.notes()) std::printf("note        %s\n", n.c_str());
}

void runInfo(const InfoOptions& o) {
  const std::string spec = o.file.empty() ? defaultVolumeSpec() : o.file;
  const Volume v =
      readVolume(spec, {.dicomSeries = o.series, .time = o.time, .channel = o.channel});
  if (o.json) {
    std::printf("%s\n", session::volumeInfo(spec, v, o.time, o.channel).dump(2).c_str());
    return;
  }
  // An OME-Zarr store: its levels, chunks and codec beside the level read.
  std::unique_ptr<ZarrStore> store;
  if (isZarrStore(spec)) {
    store = std::make_unique<ZarrStore>(openZarrStorage(spec),
                                        ZarrSelection{.time = o.time, .channel = o.channel});
  }
  const Histogram h = Histogram::compute(v, 256);
  // A DICOM folder may hold several series: list them so --series can pick.
  std::vector<DicomSeriesInfo> series;
  std::error_code ec;
  // A file of a DICOM series: the series (and stacks) beside it.
  if (std::filesystem::is_directory(spec, ec) || (std::filesystem::is_regular_file(spec, ec) &&
                                                  v.description().starts_with("DICOM series "))) {
    series = listDicomSeries(spec);
  }
  // A DICOMweb series: its stacks (a multi-frame object may hold several).
  if (isDicomWebSeriesUrl(spec)) series = listDicomWebSeries(spec);
  const ValueRange r = v.valueRange();
  std::printf("file        %s\n", spec.c_str());
  if (!v.description().empty()) std::printf("description %s\n", v.description().c_str());
  std::printf("dims        %d x %d x %d\n", v.dims().x, v.dims().y, v.dims().z);
  std::printf("spacing     %g x %g x %g\n", v.spacing().x, v.spacing().y, v.spacing().z);
  std::printf("extent      %g x %g x %g\n", v.extent().x, v.extent().y, v.extent().z);
  std::printf("orientation %s%s%s\n", orientationOf(v.direction()).describe().c_str(),
              v.geometrySource().empty() ? "" : ", from ", v.geometrySource().c_str());
  const glm::dmat4 a = v.indexToWorld();
  for (int row = 0; row < 3; ++row) {
    std::printf("%s [%10.4f %10.4f %10.4f %10.4f]\n", row == 0 ? "affine (RAS)" : "            ",
                a[0][row], a[1][row], a[2][row], a[3][row]);
  }
  std::printf("type        %s\n", std::string(scalarTypeName(v.type())).c_str());
  std::printf("modality    %s\n", v.modality().empty() ? "unknown" : v.modality().c_str());
  std::printf("values      %g .. %g (mean %.4g)\n", r.min, r.max, h.mean());
  if (const std::uint64_t bad = v.nonFiniteCount()) {
    std::printf("missing     %llu NaN/Inf voxels (%.2f %%), rendered transparent\n",
                static_cast<unsigned long long>(bad), 100.0 * bad / v.voxelCount());
  }
  std::printf("percentiles 1%%: %.4g  50%%: %.4g  99%%: %.4g\n", h.percentile(0.01),
              h.percentile(0.5), h.percentile(0.99));
  for (const auto& s : series) {
    std::printf(
        "series      %s: %d slices, %s%s\n", s.selector().c_str(), s.slices, s.description.c_str(),
        v.description().rfind("DICOM series " + s.selector() + " ", 0) == 0 ? " (read)" : "");
  }
  if (store) printZarrLevels(*store);
  std::printf("bytes       %s (%llu)\n", formatBytes(v.byteSize()).c_str(),
              static_cast<unsigned long long>(v.byteSize()));
  // A 16-bin sketch of the histogram, log-scaled, so skew is visible at a glance.
  const auto& c = h.counts();
  std::printf("histogram   ");
  const char* bars[] = {" ", "_", ".", "-", "=", "+", "*", "#"};
  std::uint64_t peak = 1;
  std::vector<std::uint64_t> coarse(16, 0);
  for (std::size_t i = 0; i < c.size(); ++i) coarse[i * 16 / c.size()] += c[i];
  for (auto x : coarse) peak = std::max(peak, x);
  for (auto x : coarse) {
    const double f =
        x == 0 ? 0.0
               : std::log(1.0 + static_cast<double>(x)) / std::log(1.0 + static_cast<double>(peak));
    std::printf("%s", bars[std::min(7, static_cast<int>(f * 7.999))]);
  }
  std::printf("  (16 bins, log scale)\n");
}
}  // namespace

void addInfoCommand(CLI::App& app) {
  auto opts = std::make_shared<InfoOptions>();
  CLI::App* cmd =
      app.add_subcommand("info",
                         "Print a volume's dims, spacing, orientation and index-to-world affine "
                         "(RAS+ mm), type, value range, histogram summary and bytes. Reads: " +
                             readExtensionsText());
  addVolumeOptions(cmd, opts->file, opts->series);
  addTimeChannelOptions(cmd, opts->time, opts->channel);
  cmd->add_flag("--json", opts->json, "Print one JSON object");
  cmd->callback([opts] { runInfo(*opts); });
}

}  // namespace tessera::app
