#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"

namespace tessera {

// PVM, the format of Roettger's volume library (V^3): "PVM", "PVM2" and
// "PVM3" headers (dims, spacing (PVM2+), components 1 or 2 = u8/u16 big
// endian); the DDS-compressed variant ("DDS v3d"/"DDS v3e") is decoded if
// supported, otherwise an InputError says it is not.
Volume readPvm(const std::filesystem::path& path);
// Writes uncompressed PVM3 (u8 as 1 component, u16 as 2 big-endian; other
// types are an InputError).
void writePvm(const Volume& volume, const std::filesystem::path& path);

// Raw voxels with a JSON sidecar (`data.raw` + `data.raw.json` or
// `data.json`): {"dims": [x,y,z], "type": "u8"|"u16"|"i16"|"f32",
// "spacing": [..], "origin": [..], "endian": "little"|"big", "offset": n}.
Volume readRawWithSidecar(const std::filesystem::path& path);
// Writes `path` (raw, little endian) and `path` + ".json".
void writeRawWithSidecar(const Volume& volume, const std::filesystem::path& path);

}  // namespace tessera
