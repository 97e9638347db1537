#pragma once
// DICOM series -> one volume, through DCMTK (Schultz 2016, 6.1 and 7.1.1).
// The browser build, which has no DCMTK, implements these with the reader
// of DicomBasicReader.h (uncompressed and RLE only); both share the series
// assembly and geometry described here (io/DicomSeries.cpp).
#include <filesystem>
#include <string>
#include <vector>

#include "tessera/core/Volume.h"

namespace tessera {

struct DicomSeriesInfo {
  std::string seriesInstanceUid;
  std::string description;  // SeriesDescription, modality
  int slices = 0;
  // A series of several stacks (a multi-frame object's Stack IDs, or its
  // orientations) is listed once per stack; "" when it has one.
  std::string stack;
  // What `--series` takes to read it: the UID, or "UID:stack".
  std::string selector() const {
    return stack.empty() ? seriesInstanceUid : seriesInstanceUid + ":" + stack;
  }
};

// Reads the series in a folder (a directory of slice files, not searched
// recursively; non-DICOM files are skipped), the series a single slice file
// belongs to (read from the files beside it), or the given files.
//
// Which series: the one named by `seriesUid`; else, for a file, its own
// series (by Series Instance UID; files without one form one group) and
// within it its own stack (same size, frame count, pixel type, orientation
// and pixel spacing; the others are left out with a note); else, for a
// folder, the series with the most slices. The description names the
// others found. A file named on its own (no `seriesUid`) that its series
// cannot hold (other files of its stack at its position, or no Image
// Position (Patient) to order it among them) is read as if alone in its
// folder, with a note on stderr and in the description naming it and the
// reason; its own errors still refuse it, and a folder keeps the error.
// Any other series that cannot be read (a broken, missing or misplaced
// slice) is an error, never a volume short of a slice; beside a named file
// it names that file as well as the file at fault.
//
// Geometry (PS3.3 C.7.6.2), converted from DICOM's LPS+ to the volume's
// RAS+ (x and y negated, core/PatientFrame.h): index x runs along Image
// Orientation (Patient)'s row vector, y along its column vector, z from
// slice to slice; voxels are stored as in the files, never flipped. Slices
// are sorted by position along the normal (row x column), duplicate,
// missing or unevenly spaced slices being an InputError naming two files;
// z then runs the way Instance Number grows when every slice has one and
// they fall along the normal, else along the normal (so a left-handed
// volume written by writeDicomSeries reads back with its own affine). The z
// axis of the affine is the actual step between consecutive positions: a
// tilted gantry (positions drifting within the slice plane by the same
// amount each slice) gives a sheared affine; positions off that straight
// line are an InputError. Pixel Spacing gives x and y spacing (row spacing
// first). Fallbacks, each noted in geometrySource(): no Image Orientation
// (Patient) on any slice means axial (1\0\0\0\1\0); a single slice has
// its normal as z axis with Spacing Between Slices, else Slice Thickness,
// else 1 mm; no Image Position (Patient) on a single slice means origin 0
// (several slices need it to be ordered).
//
// Pixels: 8/16-bit signed/unsigned, one sample; bytes after Rows x Columns
// (less than another frame) are padding and ignored. Each slice's rescale
// slope/intercept is applied: integer slopes and intercepts keep an integer
// type (u8, i16, u16) when the values fit, anything else gives f32.
// Transfer syntaxes DCMTK decodes (JPEG baseline/extended/lossless, JPEG-LS,
// RLE, deflate) are supported; others (JPEG 2000) are an InputError naming
// the file and the syntax, at once. The attributes read here are also
// understood when a writer stored them with VR UN (PS3.5 6.2.2).
//
// Files of the folder that cannot be used (truncated, undecodable) are
// skipped and counted in the description; one of the series read is an
// error unless it sits at the position of a slice that was read, or neither
// has a position (another encoding or a broken copy of that slice).
// Multi-frame files and colour are refused.
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
// span the value range (unless the options give one; see
// dicomQuantisationError). Geometry in LPS: Image Orientation (Patient) is
// the index x and y directions (the nearest orthonormal pair if they are
// not perpendicular), Image Position (Patient) of slice k is voxel (0,0,k)'s
// centre, Instance Number is k + 1, Slice Location the position along the
// normal, Spacing Between Slices and Slice Thickness the step along it; so
// readDicomSeries gives back the volume's affine, also a left-handed or
// sheared one (a single slice gets its normal as z axis). The files are
// written into a hidden temporary folder first: a new `folder` appears by
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

// The largest |value read back - value| that writeDicomSeries(volume, ...,
// options) followed by readDicomSeries would give: 0 for integer volumes
// (and f32 volumes of integers) that fit the pixel type, about half a
// quantisation step (range / 65535 / 2) for other f32 volumes. For
// `convert` to say "f32 -> DICOM is lossy: max error 0.0035". Throws what
// writeDicomSeries would (values that do not fit, non-finite values).
double dicomQuantisationError(const Volume& volume, const DicomWriteOptions& options = {});

}  // namespace tessera
