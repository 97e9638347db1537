#pragma once
// Entry point for loading volumes: picks the reader from the file name, or a
// procedural source from a "gen:" spec.
#include <filesystem>
#include <string>
#include <vector>

#include "tessera/core/Volume.h"
#include "tessera/io/ByteSource.h"

namespace tessera {

// Picks the reader from the format registry (FormatRegistry.h, listed by
// `tessera formats`): by extension, the content deciding when the extension
// is unknown or contradicts it (`scan.dat` holding a NIfTI opens as NIfTI);
// a folder is an OME-Zarr store (.zgroup/.zattrs/.zarray) or a DICOM series,
// an http(s):// URL a DICOMweb series when it ends in /studies/UID/series/UID
// (io/DicomWeb.h), else an OME-Zarr store (the finest level that fits the host
// budget, see io/ZarrStore.h); "gen:" specs are generated (io/Procedural.h).
// DICOM is read by the preferred decoder that decodes the series
// (DicomDecoder.h: DCMTK natively). Throws InputError naming the file and
// the problem; never allocates more than the file can justify or the host
// budget allows.
struct ReadOptions {
  // DICOM: the Series Instance UID to read from a folder holding several
  // (empty: the series with the most slices). An InputError for other formats.
  std::string dicomSeries;
  // OME-Zarr: the time point and channel of a 4D/5D image (0: the first).
  // An InputError for other formats when not 0.
  int time = 0;
  int channel = 0;
};

Volume readVolume(const std::string& spec, const ReadOptions& options = {});

// A file whose format holds time series (4-D NIfTI) or an OME-Zarr store
// with a t axis: how many time points it holds (1 for any other file,
// folder or spec), and time point `time` of it (of a store: channel
// `channel`, the finest level that fits the host budget), read as
// readVolume does but without its note (what a time-series player reads
// ahead with). InputError as readVolume.
int timePointCount(const std::string& spec);
Volume readTimePoint(const std::string& spec, int time, int channel = 0);

// The same choice and readers on a byte source, the other files it names
// found in `files`: what the browser reads picked or dropped files with.
// DICOM: the series of `file` from the files beside it, by the first decoder
// that decodes it and reads where the files are (files in memory: the
// reader without DCMTK, DicomBasicReader.h).
Volume readVolume(const ByteSource& file, const FileSet& files);
// The time points of such a file (1 unless its format holds time series)
// and time point `time` of it (InputError out of range, as above).
int timePointCount(const ByteSource& file);
Volume readTimePoint(const ByteSource& file, const FileSet& files, int time);

// Of several files opened together (the browser's picker or a drop), the
// one to read: a header that names the others (a .json sidecar, .nhdr,
// .mhd, .hdr) before a self-contained file, before data files (.raw, .img,
// .zraw); the first of equals. Empty `names`: an InputError.
std::string volumeFileAmong(const std::vector<std::string>& names);

}  // namespace tessera
