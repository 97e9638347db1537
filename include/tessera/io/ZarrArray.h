#pragma once
// One Zarr v2 array: its `.zarray` metadata (shape, chunks, dtype, byte
// order, fill_value, dimension_separator, compressor) and its chunk codecs.
// Spec: Zarr storage specification version 2 ("Metadata", "Chunk keys",
// "Data type encoding"); the compressors are numcodecs' zlib, gzip, zstd and
// blosc, decoded and encoded by Debian's zlib, libzstd and libblosc.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "tessera/core/ScalarType.h"

namespace tessera {

enum class ZarrCompressor { None, Zlib, Gzip, Zstd, Blosc };

// "none", "zlib", "gzip", "zstd", "blosc"; InputError listing the choices.
ZarrCompressor parseZarrCompressor(const std::string& name);

struct ZarrArrayMeta {
  std::vector<std::int64_t> shape;   // array axes, slowest first
  std::vector<std::int64_t> chunks;  // same rank as shape
  std::string dtype;                 // as written, e.g. "<u2"
  char kind = 'u';                   // 'b', 'i', 'u', 'f'
  int itemSize = 1;                  // bytes per element in a chunk
  bool bigEndian = false;            // '>' (only when itemSize > 1)
  // What Tessera holds the values as: u1/u2/i2/f4 as themselves, every
  // other dtype as f32 (`converted`; a note says so).
  ScalarType target = ScalarType::U8;
  bool converted = false;
  double fill = 0.0;  // null reads as 0; "NaN"/"Infinity"/"-Infinity" for floats
  char separator = '.';
  ZarrCompressor compressor = ZarrCompressor::None;
  std::string compressorText;  // for `info`: "blosc lz4 shuffle", "zlib", ...

  int rank() const { return static_cast<int>(shape.size()); }
  // Elements in one chunk (every chunk, edge ones too, holds that many).
  std::uint64_t chunkElements() const;
  std::uint64_t chunkBytes() const { return chunkElements() * std::uint64_t(itemSize); }
  // The largest stored chunk accepted: chunkBytes plus the worst expansion
  // of any supported compressor on incompressible data.
  std::uint64_t maxStoredChunkBytes() const;
  // Chunks along array axis `a`: ceil(shape / chunks).
  std::int64_t chunkCount(int a) const { return (shape[a] + chunks[a] - 1) / chunks[a]; }
  // The key of the chunk with grid index `index` (relative to the array).
  std::string chunkKey(std::span<const std::int64_t> index) const;
};

// Parses a `.zarray` document; `name` (the file or URL) starts every error.
// Checks ranks, positive shapes and chunks, one chunk's bytes against the
// host budget, and that the dtype, order and compressor are readable.
ZarrArrayMeta parseZarray(std::string_view json, const std::string& name);

// The `.zarray` document for an array Tessera writes (order C, fill 0,
// separator "/", filters null).
std::string zarrayJson(const std::vector<std::int64_t>& shape,
                       const std::vector<std::int64_t>& chunks, ScalarType type,
                       ZarrCompressor compressor);

// A stored chunk -> exactly meta.chunkBytes() bytes in the array's own byte
// order. InputError naming `where` (the chunk's key, path or URL) for a
// truncated or corrupt stream or a decompressed size other than expected.
std::vector<std::byte> decodeZarrChunk(const ZarrArrayMeta& meta, std::span<const std::byte> stored,
                                       const std::string& where);

// A chunk its storage decoded already (ZarrStorage::decodesChunks): checked
// to hold exactly meta.chunkBytes() bytes (InputError naming `where`).
std::vector<std::byte> decodedZarrChunk(const ZarrArrayMeta& meta, std::vector<std::byte> raw,
                                        const std::string& where);

// Raw little-endian chunk bytes -> the stored form (blosc: lz4 + byte
// shuffle of `itemSize`-byte elements; zstd level 3; zlib level 6).
std::vector<std::byte> encodeZarrChunk(ZarrCompressor compressor, int itemSize,
                                       std::span<const std::byte> raw);

}  // namespace tessera
