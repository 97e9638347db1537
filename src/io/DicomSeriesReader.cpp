// PLACEHOLDER until the DICOM reader lands (issue 7); replaced wholesale.
#include "tessera/io/DicomSeriesReader.h"

#include "tessera/core/Error.h"

namespace tessera {
Volume readDicomSeries(const std::filesystem::path& p, const std::string&) {
  throw InputError(p.string() + ": is a directory; DICOM series are not supported yet");
}
Volume readDicomFiles(const std::vector<std::filesystem::path>&, const std::string&) {
  throw InputError("DICOM is not supported yet");
}
std::vector<DicomSeriesInfo> listDicomSeries(const std::filesystem::path&) {
  return {};
}
void writeDicomSeries(const Volume&, const std::filesystem::path&, const DicomWriteOptions&) {
  throw InputError("DICOM writing is not supported yet");
}
}  // namespace tessera
