#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"

namespace tessera {

// .mha: header and voxels in one file; .mhd: header plus <stem>.raw (or
// <stem>.zraw when compressed) beside it. Little endian, one zlib stream
// when compressed; TransformMatrix, Offset (LPS, %.17g), ElementSpacing and
// the matching AnatomicalOrientation (MetaIO's letters: "RAI" for identity).
void writeMetaImage(const Volume& volume, const std::filesystem::path& path,
                    bool compressed = false);

}  // namespace tessera
