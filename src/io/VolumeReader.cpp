#include "tessera/io/VolumeReader.h"

#include <cstdio>

#include "io/HeaderText.h"
#include "tessera/core/Error.h"
#include "tessera/io/DicomDecoder.h"
#include "tessera/io/DicomWeb.h"
#include "tessera/io/FormatRegistry.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/ZarrStore.h"

namespace tessera {

namespace {

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string lowerFileName(const std::string& name) {
  return io_detail::lower(std::filesystem::path(name).filename().string());
}

}  // namespace

Volume readVolume(const std::string& spec, const ReadOptions& options) {
  auto notDicom = [&] {
    if (!options.dicomSeries.empty()) {
      throw InputError(spec + ": a DICOM series (" + options.dicomSeries +
                       ") was asked for, but this is not DICOM");
    }
  };
  // A DICOMweb series URL is a DICOM series (before any other URL, which
  // is an OME-Zarr store).
  if (isDicomWebSeriesUrl(spec)) {
    dicomWebStack(spec, options.dicomSeries);  // refuses another series than the URL's
    if (options.time != 0 || options.channel != 0) {
      throw InputError(spec +
                       ": --time/--channel select within an OME-Zarr store; this is not one");
    }
    return readDicomWebSeries(spec, nullptr, options.dicomSeries);
  }
  if (isZarrStore(spec)) {
    notDicom();
    std::string note;
    Volume v = readZarrVolume(spec, {.time = options.time, .channel = options.channel}, &note);
    // Which level was read, and what was converted, is for the user to know.
    std::fprintf(stderr, "note: %s: %s\n", spec.c_str(), note.c_str());
    return v;
  }
  if (options.channel != 0) {
    throw InputError(spec + ": --channel selects within an OME-Zarr store; this is not one");
  }
  auto noTime = [&] {
    if (options.time != 0) {
      throw InputError(spec +
                       ": --time selects a time point of an OME-Zarr store or a 4-D NIfTI file; "
                       "this is neither");
    }
  };
  if (spec.rfind("gen:", 0) == 0) {
    notDicom();
    noTime();
    return makeProcedural(spec);
  }
  const std::filesystem::path path(spec);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    throw InputError(spec +
                     ": no such file (or use gen:sphere, gen:shepp-logan, gen:marschner-lobb)");
  }
  // A folder is a DICOM series (the only file format that is a folder; an
  // OME-Zarr store was recognised above by its metadata files).
  if (std::filesystem::is_directory(path, ec)) {
    noTime();
    return readDicomFolder(path, options.dicomSeries);
  }
  const FileSource file(path);
  const VolumeFormat& format = chooseReadFormat(file);
  // DICOM from disk: the decoder that reads every syntax of the series
  // (DCMTK in the native build), from the files beside it.
  if (format.id == "dicom") {
    noTime();
    return readDicomFolder(path, options.dicomSeries);
  }
  notDicom();
  if (!format.timePoints) {
    noTime();
    return format.read(file, FolderFiles());
  }
  // A time series: which time point is shown, of how many, is for the
  // user to know (the default is the first).
  const int timePoints = format.timePoints(file);
  Volume v = format.readTimePoint(file, FolderFiles(), options.time);
  if (timePoints > 1) {
    std::fprintf(stderr,
                 "note: %s: %d time points; reading time point %d (--time T reads another)\n",
                 spec.c_str(), timePoints, options.time);
  }
  return v;
}

namespace {

// A file (not a spec, folder or store) whose format holds time series.
bool mayHoldTimeSeries(const std::string& spec) {
  std::error_code ec;
  return spec.rfind("gen:", 0) != 0 && !isZarrStore(spec) &&
         std::filesystem::is_regular_file(spec, ec);
}

}  // namespace

int timePointCount(const std::string& spec) {
  if (isZarrStore(spec)) return ZarrStore(openZarrStorage(spec)).timePoints();
  if (!mayHoldTimeSeries(spec)) return 1;
  const FileSource file{std::filesystem::path(spec)};
  const VolumeFormat& format = chooseReadFormat(file);
  return format.timePoints ? format.timePoints(file) : 1;
}

Volume readTimePoint(const std::string& spec, int time, int channel) {
  if (isZarrStore(spec)) return readZarrVolume(spec, {.time = time, .channel = channel});
  if (mayHoldTimeSeries(spec)) {
    const FileSource file{std::filesystem::path(spec)};
    const VolumeFormat& format = chooseReadFormat(file);
    if (format.readTimePoint) return format.readTimePoint(file, FolderFiles(), time);
  }
  return readVolume(spec, {.dicomSeries = "", .time = time, .channel = channel});
}

Volume readVolume(const ByteSource& file, const FileSet& files) {
  // By extension, the content deciding when the extension is unknown or
  // contradicts it (FormatRegistry.h); DICOM through the decoder that
  // decodes the series and reads where its files are (DicomDecoder.h).
  return chooseReadFormat(file).read(file, files);
}

int timePointCount(const ByteSource& file) {
  const VolumeFormat& format = chooseReadFormat(file);
  return format.timePoints ? format.timePoints(file) : 1;
}

Volume readTimePoint(const ByteSource& file, const FileSet& files, int time) {
  const VolumeFormat& format = chooseReadFormat(file);
  if (format.readTimePoint) return format.readTimePoint(file, files, time);
  if (time != 0) {
    throw InputError(file.name() + ": time point " + std::to_string(time) +
                     " asked for; the file holds one volume");
  }
  return format.read(file, files);
}

std::string volumeFileAmong(const std::vector<std::string>& names) {
  if (names.empty()) throw InputError("no file to read");
  auto rank = [](const std::string& name) {
    const std::string n = lowerFileName(name);
    for (const char* header : {".json", ".nhdr", ".mhd", ".hdr", ".hdr.gz"}) {
      if (endsWith(n, header)) return 0;
    }
    for (const char* data : {".raw", ".img", ".img.gz", ".zraw"}) {
      if (endsWith(n, data)) return 2;
    }
    return 1;
  };
  const std::string* best = &names.front();
  for (const std::string& n : names) {
    if (rank(n) < rank(*best)) best = &n;
  }
  return *best;
}

}  // namespace tessera
