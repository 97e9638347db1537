#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"

namespace tessera {

// Writes NIfTI-1 (.nii, or gzip-compressed .nii.gz; other names are an
// InputError) with a header built by nifticlib: dims (at most 32767 per
// axis), datatype from the scalar type (uint8, uint16, int16, float32),
// pixdim = spacing, the index-to-world affine (RAS, as NIfTI) in the sform
// and its nearest rotation in the qform (qfac -1 for reflections), both with
// the xform code of a NIfTI source, else 1 (scanner) — see
// io/NiftiGeometry.h; scl_slope 0; voxels as stored (never flipped), in
// native byte order. Written to a temporary
// file beside `path` and renamed, so a failed write (Error naming the path)
// leaves no partial file.
void writeNifti(const Volume& volume, const std::filesystem::path& path);

}  // namespace tessera
