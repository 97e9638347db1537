#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"

namespace tessera {

// Writes NIfTI-1 (.nii or .nii.gz) through nifticlib: dims, spacing
// (pixdim), origin (qoffset), datatype from the scalar type.
void writeNifti(const Volume& volume, const std::filesystem::path& path);

}  // namespace tessera
