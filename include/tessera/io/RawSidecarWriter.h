#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"

namespace tessera {

// Writes `path` (raw, little endian) and `path` + ".json" (naming `path` in
// "file", with spacing, origin and direction), both through temporary files
// renamed once complete.
void writeRawWithSidecar(const Volume& volume, const std::filesystem::path& path);

}  // namespace tessera
