#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"

namespace tessera {

// NRRD (.nrrd with attached data, .nhdr with detached "data file:"),
// encodings raw and gzip, endian little/big, types uchar/ushort/short/float
// (and their aliases; signed char is widened to i16, int/uint/double are
// converted to f32), dimension 3 (or 4 with a size-1 first or last axis),
// fields: sizes, type, encoding, endian, spacings or space directions,
// space origin, byte skip (>= 0, or -1 for raw data at the end of the file),
// line skip. Multi-file data ("LIST", formatted names) is refused.
Volume readNrrd(const std::filesystem::path& path);

// Writes a NRRD file (attached, raw or gzip encoding, little endian) — used by
// tests and tools to produce fixtures. Spacing is written as diagonal "space
// directions" (so "space origin" is legal), which readNrrd turns back into
// the same spacing; dims, type, spacing, origin and voxels round-trip exactly.
// Throws Error if the file cannot be written.
void writeNrrd(const Volume& volume, const std::filesystem::path& path, bool gzip = false);

}  // namespace tessera
