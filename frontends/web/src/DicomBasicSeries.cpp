// The browser build has no DCMTK: DICOM series (a folder in the module's
// file system, or files given by path) are read by the reader that needs
// none (io/DicomBasicReader.h: uncompressed and RLE Part-10 files). Dropped
// and picked files take the byte-source path (readVolume on a FileSet),
// which reads DICOM with the same reader.
#include "tessera/io/DicomBasicReader.h"
#include "tessera/io/DicomSeriesReader.h"

namespace tessera {

Volume readDicomSeries(const std::filesystem::path& folderOrFile, const std::string& seriesUid) {
  return readDicomSeriesBasic(folderOrFile, seriesUid);
}

Volume readDicomFiles(const std::vector<std::filesystem::path>& files,
                      const std::string& seriesUid) {
  return readDicomFilesBasic(files, seriesUid);
}

std::vector<DicomSeriesInfo> listDicomSeries(const std::filesystem::path& folder) {
  return listDicomSeriesBasic(folder);
}

}  // namespace tessera
