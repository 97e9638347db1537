#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"

namespace tessera {

// Writes NIfTI-1 (.nii, or gzip-compressed .nii.gz; other names are an
// InputError) with a header built by nifticlib: dims (at most 32767 per
// axis), datatype from the scalar type (uint8, uint16, int16, float32),
// pixdim = spacing, qform (code 1, identity rotation) with qoffset = origin,
// no sform, scl_slope 0; voxels in native byte order. Written to a temporary
// file beside `path` and renamed, so a failed write (Error naming the path)
// leaves no partial file.
void writeNifti(const Volume& volume, const std::filesystem::path& path);

}  // namespace tessera
