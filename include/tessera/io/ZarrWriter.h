#pragma once
// Writes an OME-Zarr store (OME-NGFF 0.4 multiscales on Zarr v2, or 0.5 on
// Zarr v3, optionally sharded): a
// pyramid from the finest level down to one chunk, each level dividing
// each axis of the one before by its factor (2 on every axis by default;
// microscopy's (1, 2, 2), z y x, keeps z), streamed slab by slab so that
// host memory holds one chunk-deep slab per level, never the volume.
//
// The reduction filter is the mean over a block of the factors (2x2x2 by
// default; partial blocks at odd edges average the voxels present; NaN is
// skipped), exactly lod::downsample(v, factors): it is what the renderer's
// own pyramid uses, so a level read from the
// store equals the level Tessera would compute in-core; it is the box
// filter whose voxel centre sits half a voxel of the finer level into the
// block, which NGFF's per-level translation states; and, unlike taking
// every other voxel, it does not alias thin structures away. Integer types
// round to nearest.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vector_relational.hpp>

#include "tessera/core/Volume.h"
#include "tessera/io/ZarrArray.h"

namespace tessera {

struct OmeZarrWriteOptions {
  int chunk = 64;  // chunk edge in voxels (capped per axis at a level's size)
  // Per-axis chunk (x, y, z) instead of a cube of `chunk` where set (every
  // axis > 0): microscopy stores' 512x512x32. Capped the same way.
  glm::ivec3 chunkShape{0};
  // The chunk this asks for on each axis (x, y, z).
  glm::ivec3 chunkXyz() const {
    return glm::all(glm::greaterThan(chunkShape, glm::ivec3(0))) ? chunkShape : glm::ivec3(chunk);
  }
  int levels = 0;  // 0: down to a level that fits one chunk
  // Each level's factor per axis (x, y, z) against the one before: 1 (the
  // axis kept) or 2, at least one 2. (2, 2, 1) is microscopy's (1, 2, 2).
  glm::ivec3 factors{2};
  ZarrCompressor compressor = ZarrCompressor::Zstd;
  // 2: NGFF 0.4 on Zarr v2; 3: NGFF 0.5 on Zarr v3 (zlib is written as
  // gzip there, v3 having no zlib codec).
  int zarrFormat = 2;
  // Zarr v3: chunks per shard edge (sharding_indexed, index at the end with
  // a crc32c); 0 = unsharded. A shard is appended to as its slabs stream
  // by, so memory stays one chunk-deep slab per level.
  int shard = 0;
  // Called with the fraction of the finest level's slices done.
  std::function<void(double fraction, const std::string& what)> progress;
};

// z slices [z0, z1) of the finest level, as a Volume of dims.x x dims.y x
// (z1 - z0) voxels of the shape's type.
using SlabReader = std::function<Volume(int z0, int z1)>;

struct OmeZarrWriteResult {
  std::vector<glm::ivec3> levelDims;
  std::uint64_t chunksWritten = 0;
  std::uint64_t chunksSkipped = 0;  // all zero (= fill_value): not stored
  std::uint64_t bytesWritten = 0;
  ValueRange range;
};

// The number of levels `auto` gives: reduce until every axis that the
// factors (x, y, z; 2 by default) reduce fits one chunk, or no axis can
// reduce further.
int omeZarrAutoLevels(glm::ivec3 dims, int chunk);
int omeZarrAutoLevels(glm::ivec3 dims, glm::ivec3 chunk, glm::ivec3 factors = glm::ivec3(2));

// Writes the store at `path` (a folder, by convention NAME.ome.zarr): built
// in a temporary folder beside it and renamed into place when complete; an
// existing OME-Zarr store there is replaced, anything else is an error.
// `shape` gives dims, type, geometry and window.
OmeZarrWriteResult writeOmeZarr(const Volume& shape, const SlabReader& slabs,
                                const std::filesystem::path& path,
                                const OmeZarrWriteOptions& options);
OmeZarrWriteResult writeOmeZarr(const Volume& volume, const std::filesystem::path& path,
                                const OmeZarrWriteOptions& options = {});

// True when `path` names an OME-Zarr output (".zarr", ".ome.zarr", maybe
// with a trailing "/").
bool isOmeZarrName(const std::filesystem::path& path);

}  // namespace tessera
