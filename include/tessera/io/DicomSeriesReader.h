#pragma once
// DICOM series -> one volume, through DCMTK (Schultz 2016, 6.1 and 7.1.1).
#include <filesystem>
#include <string>
#include <vector>

#include "tessera/core/Volume.h"

namespace tessera {

struct DicomSeriesInfo {
  std::string seriesInstanceUid;
  std::string description;  // SeriesDescription, modality
  int slices = 0;
};

// Reads the series in `folder` (a directory of slice files) or the given
// files: slices sorted by position along the slice normal (not by name),
// spacing from the positions, rescale slope/intercept applied, 8/16-bit
// signed/unsigned. When a folder holds several series, the one named by
// `seriesUid` is read (empty: the series with the most slices), and the
// description says which others were found. Transfer syntaxes DCMTK decodes
// (JPEG, JPEG-LS, RLE, deflate) are supported; others are an InputError
// naming the file and the syntax.
Volume readDicomSeries(const std::filesystem::path& folderOrFile,
                       const std::string& seriesUid = "");
Volume readDicomFiles(const std::vector<std::filesystem::path>& files,
                      const std::string& seriesUid = "");

// The series found in a folder (for `tessera info` and error messages).
std::vector<DicomSeriesInfo> listDicomSeries(const std::filesystem::path& folder);

// Writes `volume` as a series of single-frame DICOM files (CT Image Storage
// or MR), one per z-slice, into `folder` (for tests and conversion).
struct DicomWriteOptions {
  std::string seriesInstanceUid;  // empty: generated
  std::string seriesDescription = "tessera";
  double rescaleSlope = 1.0;
  double rescaleIntercept = 0.0;
  bool shuffleFileNames = false;                          // names unrelated to slice order
  std::string transferSyntax = "little-endian-explicit";  // or "jpeg-ls-lossless", "rle", "deflate"
};
void writeDicomSeries(const Volume& volume, const std::filesystem::path& folder,
                      const DicomWriteOptions& options = {});

}  // namespace tessera
