#include "tessera/session/VolumeInfo.h"

#include <filesystem>
#include <memory>
#include <vector>

#include "tessera/core/Histogram.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/io/DicomSeriesReader.h"
#include "tessera/io/DicomWeb.h"
#include "tessera/io/ZarrStore.h"

namespace tessera::session {

namespace {

// The index -> world (RAS+ mm) affine as 4 rows, as nibabel prints it.
nlohmann::json affineRows(const Volume& v) {
  const glm::dmat4 a = v.indexToWorld();
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({a[0][r], a[1][r], a[2][r], a[3][r]});
  return rows;
}

nlohmann::json zarrJson(const ZarrStore& store) {
  nlohmann::json levels = nlohmann::json::array();
  for (int l = 0; l < store.levelCount(); ++l) {
    const ZarrLevel& lv = store.level(l);
    levels.push_back({{"path", lv.path},
                      {"dims", {lv.dims.x, lv.dims.y, lv.dims.z}},
                      {"chunks", {lv.chunk.x, lv.chunk.y, lv.chunk.z}},
                      {"spacing", {lv.spacing.x, lv.spacing.y, lv.spacing.z}},
                      {"origin", {lv.origin.x, lv.origin.y, lv.origin.z}},
                      {"dtype", lv.array.dtype},
                      {"compressor", lv.array.compressorText}});
  }
  return {{"store", store.describe()}, {"levels", levels}, {"notes", store.notes()}};
}

}  // namespace

nlohmann::json volumeInfo(const std::string& spec, const Volume& v, int time, int channel) {
  const Histogram h = Histogram::compute(v, 256);
  const ValueRange r = v.valueRange();
  nlohmann::json j;
  j["file"] = spec;
  j["dims"] = {v.dims().x, v.dims().y, v.dims().z};
  j["spacing"] = {v.spacing().x, v.spacing().y, v.spacing().z};
  j["origin"] = {v.origin().x, v.origin().y, v.origin().z};
  const Orientation orient = orientationOf(v.direction());
  j["orientation"] = orient.code;
  j["oblique"] = orient.oblique;
  j["orientation_text"] = orient.describe();
  j["affine"] = affineRows(v);
  j["world_frame"] = "RAS";
  j["geometry_source"] = v.geometrySource();
  j["type"] = std::string(scalarTypeName(v.type()));
  j["value_min"] = r.min;
  j["value_max"] = r.max;
  j["non_finite_voxels"] = v.nonFiniteCount();
  j["mean"] = h.mean();
  j["percentiles"] = {
      {"1", h.percentile(0.01)}, {"50", h.percentile(0.5)}, {"99", h.percentile(0.99)}};
  j["bytes"] = v.byteSize();
  j["description"] = v.description();
  j["modality"] = v.modality();  // DICOM (0008,0060); "" when unknown
  // An OME-Zarr store: its levels, chunks and codec beside the level read.
  if (isZarrStore(spec)) {
    const ZarrStore store(openZarrStorage(spec), ZarrSelection{.time = time, .channel = channel});
    j["zarr"] = zarrJson(store);
  }
  // A DICOM folder may hold several series: listed so that --series can pick.
  std::error_code ec;
  // A DICOM folder, a file of a DICOM series or a DICOMweb series URL: the
  // series (and stacks) there, each with the --series value that selects it.
  if (std::filesystem::is_directory(spec, ec) || isDicomWebSeriesUrl(spec) ||
      (std::filesystem::is_regular_file(spec, ec) &&
       v.description().starts_with("DICOM series "))) {
    const std::vector<DicomSeriesInfo> series =
        isDicomWebSeriesUrl(spec) ? listDicomWebSeries(spec) : listDicomSeries(spec);
    if (!series.empty()) {
      j["dicom_series"] = nlohmann::json::array();
      for (const auto& s : series) {
        j["dicom_series"].push_back({{"series_instance_uid", s.seriesInstanceUid},
                                     {"stack", s.stack},
                                     {"select", s.selector()},
                                     {"description", s.description},
                                     {"slices", s.slices}});
      }
    }
  }
  return j;
}

}  // namespace tessera::session
