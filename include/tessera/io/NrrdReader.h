#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"

namespace tessera {

// NRRD (.nrrd with attached data, .nhdr with detached "data file:"),
// encodings raw and gzip, endian little/big, types uchar/ushort/short/float
// (and their aliases), dimension 3 (or 4 with a leading size-1 axis),
// fields: sizes, type, encoding, endian, spacings or space directions,
// space origin, byte skip (>= 0), line skip.
Volume readNrrd(const std::filesystem::path& path);

// Writes a NRRD file (attached, raw or gzip encoding) — used by tests and
// tools to produce fixtures.
void writeNrrd(const Volume& volume, const std::filesystem::path& path, bool gzip = false);

}  // namespace tessera
