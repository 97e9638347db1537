#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"
#include "tessera/io/ByteSource.h"

namespace tessera {

// MetaImage (ITK): .mha (header + data in one file) and .mhd + detached raw
// or zraw (zlib) data, looked up in `files`; MET_UCHAR/CHAR/USHORT/SHORT/
// FLOAT (and INT/UINT/DOUBLE converted to f32), NDims 3, ElementSpacing,
// Offset, BinaryDataByteOrderMSB, HeaderSize (incl. -1). Sizes are checked
// against the data before allocating.
// Also: NDims 4 with DimSize 1 last, ElementSize, Origin/Position,
// ElementByteOrderMSB, CompressedDataSize (checked against the file),
// MET_LONG/ULONG (4 bytes, to f32); HeaderSize > 0 is the offset of the
// voxels in the data file, as in MetaIO. Geometry as ITK reads it, in LPS
// converted to RAS: TransformMatrix (or Rotation/Orientation) lists each
// index axis' direction in turn, Offset (or Position/Origin) is voxel 0's
// centre; AnatomicalOrientation is ignored, as ITK does (a disagreement is
// noted in geometrySource()). Refused with an InputError: several
// channels, BinaryData = False, ElementDataFile LIST or a file-name pattern.
Volume readMetaImage(const ByteSource& header, const FileSet& files);
Volume readMetaImage(const std::filesystem::path& path);

}  // namespace tessera
