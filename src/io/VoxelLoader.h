#pragma once
// The part every reader shares once its header is parsed: check the declared
// voxel data against the file and the host budget, then read it (raw or
// gzip), swap bytes, widen or convert types and apply a linear scale.
#include <cstdint>
#include <string>
#include <string_view>

#include <glm/vec3.hpp>

#include "tessera/core/ScalarType.h"
#include "tessera/core/Volume.h"
#include "tessera/io/ByteSource.h"

namespace tessera::io_detail {

// Voxel types as stored in files; each maps to the Volume type that holds it
// without loss (int8 → i16) or, for types a Volume lacks, to f32.
enum class DiskType { U8, I8, U16, I16, U32, I32, F32, F64 };

std::size_t diskTypeSize(DiskType t);
std::string_view diskTypeName(DiskType t);  // "u8", "i32", "f64", ...
// True when the type cannot be held exactly and is converted to f32.
bool isConvertedToF32(DiskType t);

struct VoxelFormat {
  glm::ivec3 dims{0, 0, 0};
  DiskType type = DiskType::U8;
  bool bigEndian = false;
  // value = raw * slope + intercept, stored as f32, when `scaled`.
  bool scaled = false;
  double slope = 1.0;
  double intercept = 0.0;
};

ScalarType volumeTypeFor(const VoxelFormat& format);

struct VoxelSource {
  const ByteSource* file = nullptr;  // the file holding the voxel bytes
  bool gzip = false;
  // Raw: file offset of the first voxel. Gzip: file offset where the
  // compressed stream starts.
  std::uint64_t fileOffset = 0;
  // Gzip only: inflated bytes to drop before the first voxel.
  std::uint64_t inflatedSkip = 0;
  // Raw only: the voxels are the last bytes of the file (NRRD "byte skip: -1").
  bool atEndOfFile = false;
};

// Reads dims × type voxels. `what` starts every error message (usually the
// header file's name). Order of checks, none of which allocates voxel
// memory: dims sane; raw: offset + bytes ≤ file size; gzip: the host budget,
// then the deflate ratio bound. Gzip data is inflated into chunks allocated
// as bytes arrive, and only a complete stream gets a Volume.
Volume loadVoxels(const VoxelSource& source, const VoxelFormat& format, const std::string& what);

// "181x217x181"
std::string dimsString(glm::ivec3 dims);

class ByteStream;

// Reads dims × type voxels from an open stream of voxel bytes (decoded
// base64, inflated zlib blocks, a buffer) into a new Volume, with the same
// swapping and conversion as loadVoxels. The caller checks first that the
// stream can hold that many bytes (the host budget is checked here, by
// Volume::allocate); a stream that still ends early is an InputError naming
// `what`, never a half-filled volume.
Volume decodeVoxels(ByteStream& bytes, const VoxelFormat& format, const std::string& what);

}  // namespace tessera::io_detail
