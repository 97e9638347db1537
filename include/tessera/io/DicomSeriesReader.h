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

// Reads the series in a folder (a directory of slice files, not searched
// recursively; non-DICOM files are skipped), the series a single slice file
// belongs to (read from the files beside it), or the given files. Slices are
// sorted by position along the slice normal (not by name); z spacing is the
// median gap between positions, and duplicate, missing or unevenly spaced
// slices are an InputError naming the two files. The volume's x, y, z follow
// the slices' rows, columns and normal. 8/16-bit signed/unsigned pixels with
// one sample; each slice's rescale slope/intercept is applied: integer slopes
// and intercepts keep an integer type (u8, i16, u16) when the values fit,
// anything else gives f32. When a folder holds several series (by Series
// Instance UID), the one named by `seriesUid` is read (empty: the series
// with the most slices), and the description says which others were found.
// Transfer syntaxes DCMTK decodes (JPEG, JPEG-LS, RLE, deflate) are
// supported; others are an InputError naming the file and the syntax.
// Multi-frame files, colour and tilted-gantry (sheared) series are refused.
Volume readDicomSeries(const std::filesystem::path& folderOrFile,
                       const std::string& seriesUid = "");
Volume readDicomFiles(const std::vector<std::filesystem::path>& files,
                      const std::string& seriesUid = "");

// The series found in a folder (for `tessera info` and error messages), the
// largest first. Non-DICOM files are skipped; subfolders are not searched.
std::vector<DicomSeriesInfo> listDicomSeries(const std::filesystem::path& folder);

// Writes `volume` as a series of single-frame DICOM files (CT Image Storage
// or MR), one per z-slice, into `folder` (for tests and conversion).
// u8 is stored as 8-bit, u16/i16 as 16-bit unsigned/signed, with
// stored = round((value - intercept) / slope); a stored value outside the
// pixel type is an InputError. f32 is stored as 16-bit: exactly when every
// value is an integer that fits, otherwise with a slope/intercept chosen to
// span the value range (unless the options give one). Slices lie along +z:
// position = origin + z * spacing.z, orientation 1\0\0\0\1\0. The files
// are written into a hidden temporary folder first: a new `folder` appears by
// one rename, an existing one receives the finished files by rename (names
// already there are an InputError, never overwritten).
struct DicomWriteOptions {
  std::string seriesInstanceUid;  // empty: generated
  std::string seriesDescription = "tessera";
  std::string modality;  // "CT" or "MR"; empty: CT when values are rescaled or f32, else MR
  double rescaleSlope = 1.0;
  double rescaleIntercept = 0.0;
  bool shuffleFileNames = false;  // random names unrelated to slice order, else slice_%04d.dcm
  std::string transferSyntax = "little-endian-explicit";  // or "jpeg-ls-lossless", "rle", "deflate"
};
void writeDicomSeries(const Volume& volume, const std::filesystem::path& folder,
                      const DicomWriteOptions& options = {});

}  // namespace tessera
