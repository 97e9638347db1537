#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"

namespace tessera {

// MetaImage (ITK): .mha (header + data in one file) and .mhd + detached raw
// or zraw (zlib) data; MET_UCHAR/CHAR/USHORT/SHORT/FLOAT (and INT/UINT/DOUBLE
// converted to f32), NDims 3, ElementSpacing, Offset, BinaryDataByteOrderMSB,
// HeaderSize (incl. -1). Sizes are checked against the data before allocating.
Volume readMetaImage(const std::filesystem::path& path);
void writeMetaImage(const Volume& volume, const std::filesystem::path& path,
                    bool compressed = false);

}  // namespace tessera
