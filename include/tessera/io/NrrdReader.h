#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"
#include "tessera/io/ByteSource.h"

namespace tessera {

// NRRD (.nrrd with attached data, .nhdr with detached "data file:", looked
// up in `files`), encodings raw and gzip, endian little/big, types
// uchar/ushort/short/float (and their aliases; signed char is widened to
// i16, int/uint/double are converted to f32), dimension 3 (or 4 with a
// size-1 first or last axis), fields: sizes, type, encoding, endian,
// spacings or space directions, space, space dimension, space origin
// (placed in RAS as io/NrrdGeometry.h says), byte skip (>= 0, or -1 for raw
// data at the end of the file), line skip. Multi-file data ("LIST",
// formatted names) is refused.
Volume readNrrd(const ByteSource& file, const FileSet& files);
Volume readNrrd(const std::filesystem::path& path);

}  // namespace tessera
