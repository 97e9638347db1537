#pragma once
// One Zarr array: its metadata and its chunk codecs.
// Zarr v2: `.zarray` (shape, chunks, dtype, byte order, fill_value,
// dimension_separator, compressor); spec: Zarr storage specification
// version 2 ("Metadata", "Chunk keys", "Data type encoding").
// Zarr v3: the array's `zarr.json` (shape, data_type, the regular chunk
// grid, chunk_key_encoding `default` or `v2`, fill_value, and the codec
// pipeline: `transpose`, `bytes` (either endian), `gzip`, `zstd`,
// `blosc`, `crc32c`, and `sharding_indexed` with its own inner codecs and
// index codecs); spec: Zarr core specification version 3.0, "Array
// metadata", "Chunk grids", "Chunk key encoding", "Codecs", and the
// sharding codec's "Binary shard format".
// The compressors are numcodecs' zlib, gzip, zstd and blosc, decoded and
// encoded by Debian's zlib, libzstd and libblosc.
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

// A v3 bytes-to-bytes codec.
enum class ZarrBytesCodec { Gzip, Zstd, Blosc, Crc32c };

// Where an inner chunk of a shard lies in the shard's bytes (the shard
// index's entry); `missing` for the all-ones entry (= fill_value).
struct ZarrShardEntry {
  std::uint64_t offset = 0;
  std::uint64_t bytes = 0;
  bool missing() const { return offset == ~std::uint64_t{0} && bytes == ~std::uint64_t{0}; }
};

struct ZarrArrayMeta {
  int format = 2;                   // 2 (.zarray) or 3 (zarr.json)
  std::vector<std::int64_t> shape;  // array axes, slowest first
  // Same rank as shape: the chunk Tessera decodes, i.e. a sharded v3
  // array's inner chunk (the shard is `shard`).
  std::vector<std::int64_t> chunks;
  std::string dtype;       // as written, e.g. "<u2"
  char kind = 'u';         // 'b', 'i', 'u', 'f'
  int itemSize = 1;        // bytes per element in a chunk
  bool bigEndian = false;  // '>' (only when itemSize > 1)
  // What Tessera holds the values as: u1/u2/i2/f4 as themselves, every
  // other dtype as f32 (`converted`; a note says so).
  ScalarType target = ScalarType::U8;
  bool converted = false;
  double fill = 0.0;  // null reads as 0; "NaN"/"Infinity"/"-Infinity" for floats
  char separator = '.';
  ZarrCompressor compressor = ZarrCompressor::None;
  std::string compressorText;  // for `info`: "blosc lz4 shuffle", "zlib", ...
  // Zarr v3 only.
  std::vector<int> transpose;               // the transpose codec's order (empty: none)
  std::vector<ZarrBytesCodec> bytesCodecs;  // in encoding order
  std::string keyPrefix;                    // "c/" (encoding "default") or "" ("v2")
  // sharding_indexed: the shard (outer chunk) shape, empty when not
  // sharded; its index is at the end (else the start) and ends with a
  // crc32c when `indexCrc32c`.
  std::vector<std::int64_t> shard;
  bool indexAtEnd = true;
  bool indexCrc32c = false;

  int rank() const { return static_cast<int>(shape.size()); }
  // Elements in one chunk (every chunk, edge ones too, holds that many).
  std::uint64_t chunkElements() const;
  std::uint64_t chunkBytes() const { return chunkElements() * std::uint64_t(itemSize); }
  // The largest stored chunk accepted: chunkBytes plus the worst expansion
  // of any supported compressor on incompressible data.
  std::uint64_t maxStoredChunkBytes() const;
  // Chunks along array axis `a`: ceil(shape / chunks).
  std::int64_t chunkCount(int a) const { return (shape[a] + chunks[a] - 1) / chunks[a]; }
  // The key of the chunk with grid index `index` (relative to the array);
  // for a sharded array the key of the shard holding that inner chunk.
  std::string chunkKey(std::span<const std::int64_t> index) const;
  bool sharded() const { return !shard.empty(); }
  // Sharded: inner chunks per shard, the inner chunk's position in its
  // shard's index (C order), the index's bytes, and the largest shard
  // accepted (every inner chunk at its largest, plus the index).
  std::uint64_t chunksPerShard() const;
  std::uint64_t innerChunkIndex(std::span<const std::int64_t> index) const;
  std::uint64_t shardIndexBytes() const { return chunksPerShard() * 16 + (indexCrc32c ? 4 : 0); }
  std::uint64_t maxStoredShardBytes() const {
    return chunksPerShard() * maxStoredChunkBytes() + shardIndexBytes();
  }
};

// Parses an array's `zarr.json` (Zarr v3); `name` starts every error,
// which names the offending key ("codecs[1].name", "chunk_grid"). Unknown
// codecs, extensions and data types are refused with the list of what is
// read.
ZarrArrayMeta parseZarrJsonArray(std::string_view json, const std::string& name);

// The shard index read from a shard of `shardBytes` bytes: checked (its
// crc32c; every entry inside the shard, outside the index, not
// overlapping another, no longer than any encoding of an inner chunk).
// InputError naming `where` and the entry.
std::vector<ZarrShardEntry> parseShardIndex(const ZarrArrayMeta& meta,
                                            std::span<const std::byte> index,
                                            std::uint64_t shardBytes, const std::string& where);

// The index of a shard Tessera writes: entries, little-endian, crc32c.
std::vector<std::byte> encodeShardIndex(const std::vector<ZarrShardEntry>& entries);

// CRC-32C (Castagnoli), as the crc32c codec appends it.
std::uint32_t crc32c(std::span<const std::byte> bytes);

// The `zarr.json` of an array Tessera writes (Zarr v3: fill 0, the default
// chunk key encoding; sharded into `shard` when not empty, index at the
// end with a crc32c).
std::string zarrJsonArray(const std::vector<std::int64_t>& shape,
                          const std::vector<std::int64_t>& chunks,
                          const std::vector<std::int64_t>& shard, ScalarType type,
                          ZarrCompressor compressor);

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
// to hold exactly meta.chunkBytes() bytes (InputError naming `where`); a
// Zarr v3 chunk's transpose codec is undone here.
std::vector<std::byte> decodedZarrChunk(const ZarrArrayMeta& meta, std::vector<std::byte> raw,
                                        const std::string& where);

// Raw little-endian chunk bytes -> the stored form (blosc: lz4 + byte
// shuffle of `itemSize`-byte elements; zstd level 3; zlib level 6).
std::vector<std::byte> encodeZarrChunk(ZarrCompressor compressor, int itemSize,
                                       std::span<const std::byte> raw);

}  // namespace tessera
