#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"

namespace tessera {

// Writes uncompressed PVM3 (u8 as 1 component, u16 as 2 big-endian; other
// types are an InputError), with the origin in the comment string. Written
// to a temporary file and renamed, so a failure leaves no partial file.
void writePvm(const Volume& volume, const std::filesystem::path& path);

}  // namespace tessera
