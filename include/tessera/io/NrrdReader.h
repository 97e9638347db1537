#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"

namespace tessera {

// NRRD (.nrrd with attached data, .nhdr with detached "data file:"),
// encodings raw and gzip, endian little/big, types uchar/ushort/short/float
// (and their aliases; signed char is widened to i16, int/uint/double are
// converted to f32), dimension 3 (or 4 with a size-1 first or last axis),
// fields: sizes, type, encoding, endian, spacings or space directions,
// space, space dimension, space origin (placed in RAS as io/NrrdGeometry.h
// says), byte skip (>= 0, or -1 for raw data at the end of the file), line
// skip. Multi-file data ("LIST", formatted names) is refused.
Volume readNrrd(const std::filesystem::path& path);

// Writes a NRRD file (attached, raw or gzip encoding, little endian) with
// "space: left-posterior-superior" and the volume's affine as LPS "space
// directions" (direction times spacing) and "space origin", as ITK and
// Slicer write them; dims, type, affine and voxels round-trip (%.17g).
// Throws Error if the file cannot be written.
void writeNrrd(const Volume& volume, const std::filesystem::path& path, bool gzip = false);

}  // namespace tessera
