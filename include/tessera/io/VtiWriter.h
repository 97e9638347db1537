#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"

namespace tessera {

// Appended raw data, header_type UInt64, little endian, as ParaView writes;
// zlib in vtkZLibDataCompressor's 32 KiB blocks when compressed. Origin,
// Spacing and Direction hold the RAS affine unchanged.
void writeVti(const Volume& volume, const std::filesystem::path& path, bool compressed = false);

}  // namespace tessera
