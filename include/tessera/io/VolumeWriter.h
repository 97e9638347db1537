#pragma once
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "tessera/core/Volume.h"

namespace tessera {

// Writes by extension, through the format registry (FormatRegistry.h,
// formatForWriteName): .nrrd, .nii, .nii.gz, .mha, .vti, .pvm, .raw (+ .json
// sidecar), a folder name ending in .zarr (OME-Zarr), or one ending in "/"
// or ".dcm.d" for a DICOM series.
// The file appears under its final name only when complete: the writer
// writes a temporary file in the same directory and renames it, so an
// interrupted write never leaves a half-written file under the final name.
void writeVolume(const Volume& volume, const std::filesystem::path& path);

// What writing `volume` to `out` (chosen by extension, as writeVolume; the
// registry entry's lossNotes)
// would lose, as sentences for the user: geometry ("PVM stores spacing only:
// orientation LAS ... is lost") and values (f32 into DICOM's 16-bit
// integers: "... quantised, max error 0.0035"). Empty when the format holds
// the whole affine and every value (NIfTI, NRRD, MetaImage, VTI, raw + JSON;
// DICOM for integer data).
std::vector<std::string> writeLossNotes(const Volume& volume, const std::filesystem::path& out);

// Runs `write(tempPath)` and renames tempPath to `path` on success (removes
// it on failure). tempPath is in the same directory and ends with the same
// file name, so extension-based writers behave the same. A path that names
// a device or FIFO (writesInPlace: /dev/null) is written directly.
void writeAtomically(const std::filesystem::path& path,
                     const std::function<void(const std::filesystem::path&)>& write);

}  // namespace tessera
