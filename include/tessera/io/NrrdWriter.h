#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"

namespace tessera {

// Writes a NRRD file (attached, raw or gzip encoding, little endian) with
// "space: left-posterior-superior" and the volume's affine as LPS "space
// directions" (direction times spacing) and "space origin", as ITK and
// Slicer write them; dims, type, affine and voxels round-trip (%.17g).
// Throws Error if the file cannot be written.
void writeNrrd(const Volume& volume, const std::filesystem::path& path, bool gzip = false);

}  // namespace tessera
