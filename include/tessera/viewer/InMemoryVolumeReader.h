#pragma once
// Volume readers that work on bytes already in memory, for the browser,
// where files come from a picker or a drop and nifticlib/zlib/DCMTK are not
// available. Same checks as the native readers: dims x type are checked
// against the bytes present before any voxel buffer is allocated.
//
// Supported: NIfTI-1 single files (.nii; datatypes uint8, int8 -> i16,
// uint16, int16, float32, int32/uint32/float64 -> f32; scl_slope/inter
// applied), NRRD with attached data (encoding raw, or gzip once the caller
// has inflated the payload; little/big endian; uchar/char/ushort/short/
// float/int/uint/double; spacings or space directions). gzip itself is left
// to the caller (the browser's DecompressionStream): a .nii.gz must be
// inflated first, and for a gzip-encoded NRRD gzipPayloadOffset() says
// where the compressed payload starts.
#include <cstddef>
#include <optional>
#include <span>
#include <string>

#include "tessera/core/Volume.h"

namespace tessera::viewer {

// `name` is the file name (for the format and in messages). When
// `payloadInflated` is true a NRRD that says "encoding: gzip" is read as if
// its payload were raw (the caller replaced it by the inflated bytes).
// InputError naming the file and the problem.
Volume readVolumeFromMemory(const std::string& name, std::span<const std::byte> bytes,
                            bool payloadInflated = false);

// For a NRRD with attached gzip-encoded data: the offset where the
// compressed payload starts; nothing for any other input.
std::optional<std::size_t> gzipPayloadOffset(std::span<const std::byte> bytes);

// True when the bytes start with the gzip magic (1f 8b).
bool isGzip(std::span<const std::byte> bytes);

}  // namespace tessera::viewer
