#include "tessera/io/VolumeReader.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <fstream>

#include "tessera/core/Error.h"
#include "tessera/io/DicomSeriesReader.h"
#include "tessera/io/MetaImageReader.h"
#include "tessera/io/NiftiReader.h"
#include "tessera/io/NrrdReader.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/PvmReader.h"
#include "tessera/io/VtiReader.h"

namespace tessera {

namespace {
bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}
// DICOM files often have no extension: a Part-10 file has "DICM" at byte 128.
bool hasDicomMarker(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  char buf[132] = {};
  in.read(buf, sizeof buf);
  return in.gcount() == 132 && std::memcmp(buf + 128, "DICM", 4) == 0;
}
}  // namespace

Volume readVolume(const std::string& spec, const ReadOptions& options) {
  auto notDicom = [&] {
    if (!options.dicomSeries.empty()) {
      throw InputError(spec + ": a DICOM series (" + options.dicomSeries +
                       ") was asked for, but this is not DICOM");
    }
  };
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
  std::string lower = path.filename().string();
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (endsWith(lower, ".dcm") || endsWith(lower, ".ima") || hasDicomMarker(path)) {
    return readDicomSeries(path, options.dicomSeries);
  }
  notDicom();
  if (endsWith(lower, ".nii") || endsWith(lower, ".nii.gz") || endsWith(lower, ".hdr") ||
      endsWith(lower, ".hdr.gz")) {
    return readNifti(path);
  }
  if (endsWith(lower, ".nrrd") || endsWith(lower, ".nhdr")) return readNrrd(path);
  if (endsWith(lower, ".mha") || endsWith(lower, ".mhd")) return readMetaImage(path);
  if (endsWith(lower, ".vti")) return readVti(path);
  if (endsWith(lower, ".pvm")) return readPvm(path);
  if (endsWith(lower, ".raw") || endsWith(lower, ".json")) return readRawWithSidecar(path);
  throw InputError(spec +
                   ": unknown volume format (supported: .nii, .nii.gz, .hdr/.img, .nrrd, .nhdr, "
                   ".mha, .mhd, .vti, .pvm, .raw + .json sidecar, DICOM files or a DICOM folder)");
}

}  // namespace tessera
