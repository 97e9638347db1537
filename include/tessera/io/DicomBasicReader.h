#pragma once
// A small, strict DICOM series reader without DCMTK, for the browser (where
// DCMTK does not build), the byte-source entry point and the fuzzers. The
// native CLI keeps DCMTK (DicomSeriesReader.h), which reads more encodings.
//
// What it reads: Part-10 files (128-byte preamble, "DICM", file meta
// information in explicit VR little endian, PS3.10 7.1) whose dataset is
// implicit VR little endian (1.2.840.10008.1.2), explicit VR little endian
// (1.2.840.10008.1.2.1) or RLE Lossless (1.2.840.10008.1.2.5, PS3.5 Annex
// G). Any other transfer syntax (JPEG, JPEG-LS, JPEG 2000, big endian,
// deflate) is an InputError naming the file and the syntax; so is a file
// without the Part-10 header given on its own (in a folder it is skipped as
// non-DICOM). Sequences of defined or undefined length are skipped;
// encapsulated pixel data may have a basic offset table and several
// fragments.
//
// Series assembly, the checks, the geometry (LPS -> RAS) and the rescale are
// the DCMTK reader's own code (io/DicomSeries.cpp): for the files both
// read, the volume, its affine and its description (but for the transfer
// syntax's name) are the same.
//
// Safety: every length is checked against the bytes the file has before
// anything is read or allocated (RLE against the most its segments can
// decode to); nesting is bounded; every malformed element is an InputError
// naming the file, the element and its offset.
#include <filesystem>
#include <string>
#include <vector>

#include "tessera/core/Volume.h"
#include "tessera/io/ByteSource.h"
#include "tessera/io/DicomSeriesReader.h"

namespace tessera {

// As readDicomSeries (DicomSeriesReader.h): a folder (not searched
// recursively; non-DICOM files skipped, the series with the most slices
// unless `seriesUid` names one) or one slice file (its series from the files
// beside it).
Volume readDicomSeriesBasic(const std::filesystem::path& folderOrFile,
                            const std::string& seriesUid = "");

// As readDicomFiles: these files only, the series with the most slices
// unless `seriesUid` names one; each must be a DICOM image.
Volume readDicomFilesBasic(const std::vector<std::filesystem::path>& files,
                           const std::string& seriesUid = "");

// The series `named` belongs to (or `seriesUid`), from the files beside it
// in `files` (FileSet::filesBeside): the browser's dropped or picked files,
// or a folder on disk. Files beside it that are not DICOM are skipped with
// a note; `named` is read alone, with a note, when its series cannot hold
// it (as readDicomSeries).
Volume readDicomSeriesBasic(const ByteSource& named, const FileSet& files,
                            const std::string& seriesUid = "");

// The series in a folder, the largest first.
std::vector<DicomSeriesInfo> listDicomSeriesBasic(const std::filesystem::path& folder);

// The series (and stacks) of `named` and the files beside it in `files`, the
// largest first: what the page offers to choose among.
std::vector<DicomSeriesInfo> listDicomSeriesBasic(const ByteSource& named, const FileSet& files);

}  // namespace tessera
