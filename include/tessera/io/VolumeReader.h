#pragma once
// Entry point for loading volumes: picks the reader from the file name, or a
// procedural source from a "gen:" spec.
#include <filesystem>
#include <string>
#include <vector>

#include "tessera/core/Volume.h"
#include "tessera/io/ByteSource.h"

namespace tessera {

// Picks the reader by name: `.nii`, `.nii.gz`, `.hdr`/`.img` (NIfTI-1/2),
// `.nrrd`, `.nhdr` (NRRD), `.mha`, `.mhd` (MetaImage), `.vti` (VTK XML
// ImageData), `.pvm` (PVM), `.raw` or its `.json` sidecar (raw), a folder,
// `.dcm`/`.ima` or any file with the DICM marker (DICOM series), an
// OME-Zarr store (a folder with .zgroup/.zattrs/.zarray, or an http(s)://
// URL: the finest level that fits the host budget, see io/ZarrStore.h); or
// generates a procedural volume when `spec` starts with "gen:" (see
// io/Procedural.h). Throws InputError naming the file and the problem; never
// allocates more than the file can justify or the host budget allows.
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

// The same readers on a byte source, the other files it names found in
// `files`: what the browser reads picked or dropped files with. DICOM is read
// by the reader without DCMTK (DicomBasicReader.h: uncompressed and RLE
// Part-10 files), the series of `file` from the files beside it.
Volume readVolume(const ByteSource& file, const FileSet& files);

// Of several files opened together (the browser's picker or a drop), the
// one to read: a header that names the others (a .json sidecar, .nhdr,
// .mhd, .hdr) before a self-contained file, before data files (.raw, .img,
// .zraw); the first of equals. Empty `names`: an InputError.
std::string volumeFileAmong(const std::vector<std::string>& names);

}  // namespace tessera
