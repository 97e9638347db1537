#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"
#include "tessera/io/ByteSource.h"

namespace tessera {

// Raw voxels with a JSON sidecar (`data.raw` + `data.raw.json` or
// `data.json`; or the .json itself): {"dims": [x,y,z], "type":
// "u8"|"u16"|"i16"|"f32", "spacing": [..] (default 1), "origin": [..]
// (default 0; RAS mm), "direction": [[i], [j], [k]] (unit RAS direction of
// each index axis, default identity), "endian": "little"|"big" (default
// little), "offset": n (default 0), "file": "data.raw" (relative to the
// sidecar)}. Unknown keys, wrong JSON types, non-finite or non-positive
// spacing, a direction that is not 3 independent unit vectors, and a raw
// file whose size is not exactly offset + dims × type are InputErrors.
// `file` is the sidecar or the raw file; the other is looked up in `files`.
Volume readRawWithSidecar(const ByteSource& file, const FileSet& files);
Volume readRawWithSidecar(const std::filesystem::path& path);

}  // namespace tessera
