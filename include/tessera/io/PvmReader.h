#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"
#include "tessera/io/ByteSource.h"

namespace tessera {

// PVM, the format of Roettger's volume library (V^3): "PVM", "PVM2" and
// "PVM3" headers (dims, spacing (PVM2+), components 1 or 2 = u8/u16 big
// endian; 3/4 (RGB/RGBA) are refused), plain or DDS-compressed ("DDS v3d" /
// "DDS v3e", decoded here). PVM3's description/courtesy/comment strings go
// into the volume's description; a comment "tessera origin: x y z" (written
// by writePvm) sets the origin, which PVM itself lacks. Dims and the data
// they need are checked against the file (or the decoded stream) and the
// host budget before the volume is allocated.
Volume readPvm(const ByteSource& file);
Volume readPvm(const std::filesystem::path& path);

}  // namespace tessera
