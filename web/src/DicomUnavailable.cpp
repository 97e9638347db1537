// The browser build has no DCMTK: DICOM series are read by the native
// tessera only. readVolume on a byte source already refuses DICOM with a
// reason; these keep io/VolumeReader.cpp's path entry point linkable.
#include "tessera/core/Error.h"
#include "tessera/io/DicomSeriesReader.h"

namespace tessera {

namespace {
[[noreturn]] void unavailable(const std::string& what) {
  throw InputError(what +
                   ": DICOM is read by the native tessera only (DCMTK is not in the browser); "
                   "convert it first: tessera convert FOLDER out.nii.gz");
}
}  // namespace

Volume readDicomSeries(const std::filesystem::path& folderOrFile, const std::string&) {
  unavailable(folderOrFile.string());
}

Volume readDicomFiles(const std::vector<std::filesystem::path>& files, const std::string&) {
  unavailable(files.empty() ? std::string("DICOM") : files.front().string());
}

std::vector<DicomSeriesInfo> listDicomSeries(const std::filesystem::path& folder) {
  unavailable(folder.string());
}

}  // namespace tessera
