#include "tessera/io/VolumeReader.h"

#include <array>
#include <cstdio>
#include <cstring>

#include "io/HeaderText.h"
#include "tessera/core/Error.h"
#include "tessera/io/DicomBasicReader.h"
#include "tessera/io/DicomSeriesReader.h"
#include "tessera/io/MetaImageReader.h"
#include "tessera/io/NiftiReader.h"
#include "tessera/io/NrrdReader.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/PvmReader.h"
#include "tessera/io/RawSidecarReader.h"
#include "tessera/io/VtiReader.h"
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

bool isDicomName(const std::string& lower) {
  return endsWith(lower, ".dcm") || endsWith(lower, ".ima");
}

// DICOM files often have no extension: a Part-10 file has "DICM" at byte 128.
bool hasDicomMarker(const ByteSource& file) {
  std::array<char, 4> marker{};
  return file.read(128, reinterpret_cast<std::byte*>(marker.data()), marker.size()) == 4 &&
         std::memcmp(marker.data(), "DICM", 4) == 0;
}

}  // namespace

Volume readVolume(const std::string& spec, const ReadOptions& options) {
  auto notDicom = [&] {
    if (!options.dicomSeries.empty()) {
      throw InputError(spec + ": a DICOM series (" + options.dicomSeries +
                       ") was asked for, but this is not DICOM");
    }
  };
  if (isZarrStore(spec)) {
    notDicom();
    std::string note;
    Volume v = readZarrVolume(spec, {.time = options.time, .channel = options.channel}, &note);
    // Which level was read, and what was converted, is for the user to know.
    std::fprintf(stderr, "note: %s: %s\n", spec.c_str(), note.c_str());
    return v;
  }
  if (options.time != 0 || options.channel != 0) {
    throw InputError(spec + ": --time/--channel select within an OME-Zarr store; this is not one");
  }
  if (spec.rfind("gen:", 0) == 0) {
    notDicom();
    return makeProcedural(spec);
  }
  const std::filesystem::path path(spec);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    throw InputError(spec +
                     ": no such file (or use gen:sphere, gen:shepp-logan, gen:marschner-lobb)");
  }
  // A folder is a DICOM series (the only format that is a folder).
  if (std::filesystem::is_directory(path, ec)) return readDicomSeries(path, options.dicomSeries);
  const FileSource file(path);
  if (isDicomName(lowerFileName(spec)) || hasDicomMarker(file)) {
    return readDicomSeries(path, options.dicomSeries);
  }
  notDicom();
  return readVolume(file, FolderFiles());
}

Volume readVolume(const ByteSource& file, const FileSet& files) {
  const std::string lower = lowerFileName(file.name());
  // The reader without DCMTK (the browser has none): the file's series from
  // the files beside it.
  if (isDicomName(lower) || hasDicomMarker(file)) return readDicomSeriesBasic(file, files);
  if (endsWith(lower, ".nii") || endsWith(lower, ".nii.gz") || endsWith(lower, ".hdr") ||
      endsWith(lower, ".hdr.gz")) {
    return readNifti(file, files);
  }
  if (endsWith(lower, ".nrrd") || endsWith(lower, ".nhdr")) return readNrrd(file, files);
  if (endsWith(lower, ".mha") || endsWith(lower, ".mhd")) return readMetaImage(file, files);
  if (endsWith(lower, ".vti")) return readVti(file);
  if (endsWith(lower, ".pvm")) return readPvm(file);
  if (endsWith(lower, ".raw") || endsWith(lower, ".json")) return readRawWithSidecar(file, files);
  throw InputError(file.name() +
                   ": unknown volume format (supported: .nii, .nii.gz, .hdr/.img, .nrrd, .nhdr, "
                   ".mha, .mhd, .vti, .pvm, .raw + .json sidecar, DICOM files or a DICOM folder)");
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
