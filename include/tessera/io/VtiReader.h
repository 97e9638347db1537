#pragma once
#include <filesystem>

#include "tessera/core/Volume.h"
#include "tessera/io/ByteSource.h"

namespace tessera {

// VTK XML ImageData (.vti): the first point-data array of a 3D extent;
// formats appended (raw or base64) and inline binary (base64) and ascii;
// zlib compression (vtkZLibDataCompressor, header UInt32 or UInt64);
// types UInt8/Int8/UInt16/Int16/Float32 (Int32/UInt32/Float64 -> f32);
// Spacing, Origin, Direction (VTK 9: row-major 3x3 whose columns are the
// axes). VTK has no patient frame: its coordinates are taken as Tessera's
// RAS world as they are. Sizes are checked before allocating.
// The array is the one PointData names with Scalars=, else the first; one
// Piece covering WholeExtent; a WholeExtent that starts off 0 moves the
// origin to its first point.
Volume readVti(const ByteSource& file);
Volume readVti(const std::filesystem::path& path);

}  // namespace tessera
