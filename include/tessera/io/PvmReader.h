#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"

namespace tessera {

// PVM, the format of Roettger's volume library (V^3): "PVM", "PVM2" and
// "PVM3" headers (dims, spacing (PVM2+), components 1 or 2 = u8/u16 big
// endian; 3/4 (RGB/RGBA) are refused), plain or DDS-compressed ("DDS v3d" /
// "DDS v3e", decoded here). PVM3's description/courtesy/comment strings go
// into the volume's description; a comment "tessera origin: x y z" (written
// by writePvm) sets the origin, which PVM itself lacks. Dims and the data
// they need are checked against the file (or the decoded stream) and the
// host budget before the volume is allocated.
Volume readPvm(const std::filesystem::path& path);
// Writes uncompressed PVM3 (u8 as 1 component, u16 as 2 big-endian; other
// types are an InputError), with the origin in the comment string. Written
// to a temporary file and renamed, so a failure leaves no partial file.
void writePvm(const Volume& volume, const std::filesystem::path& path);

// Raw voxels with a JSON sidecar (`data.raw` + `data.raw.json` or
// `data.json`; or the .json itself): {"dims": [x,y,z], "type":
// "u8"|"u16"|"i16"|"f32", "spacing": [..] (default 1), "origin": [..]
// (default 0; RAS mm), "direction": [[i], [j], [k]] (unit RAS direction of
// each index axis, default identity), "endian": "little"|"big" (default
// little), "offset": n (default 0), "file": "data.raw" (relative to the
// sidecar)}. Unknown keys, wrong JSON types, non-finite or non-positive
// spacing, a direction that is not 3 independent unit vectors, and a raw
// file whose size is not exactly offset + dims × type are InputErrors.
Volume readRawWithSidecar(const std::filesystem::path& path);
// Writes `path` (raw, little endian) and `path` + ".json" (naming `path` in
// "file", with spacing, origin and direction), both through temporary files
// renamed once complete.
void writeRawWithSidecar(const Volume& volume, const std::filesystem::path& path);

}  // namespace tessera
