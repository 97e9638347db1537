#pragma once
// The chunk decoders behind decodeZarrChunk (io/ZarrArray.h), one set per
// platform: natively Debian's zlib, libzstd and libblosc
// (io/ZarrCodecs.cpp); in the browser the page's pako for zlib/gzip
// (frontends/web/src/ZarrCodecsWeb.cpp). Each returns exactly `expected` bytes or
// throws InputError naming `where` (the chunk's path or URL).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace tessera::io_detail {

// `text` (the metadata document `name`: .zarray, zarr.json) parsed as a JSON
// object whose zarr_format is `format`; InputError naming `name` otherwise.
nlohmann::json parseZarrDocument(std::string_view text, const std::string& name, int format);

// A fill_value both Zarr versions spell alike: a number, a boolean, "NaN",
// "Infinity" or "-Infinity"; nothing for anything else.
std::optional<double> zarrFillNumber(const nlohmann::json& f);

std::vector<std::byte> inflateZarrChunk(std::span<const std::byte> in, std::uint64_t expected,
                                        bool gzip, const std::string& where);
std::vector<std::byte> zstdZarrChunk(std::span<const std::byte> in, std::uint64_t expected,
                                     const std::string& where);
std::vector<std::byte> bloscZarrChunk(std::span<const std::byte> in, std::uint64_t expected,
                                      const std::string& where);

}  // namespace tessera::io_detail

namespace tessera {
struct ZarrArrayMeta;
namespace io_detail {
// A Zarr v3 chunk through its codec pipeline in reverse (io/ZarrV3.cpp):
// exactly meta.chunkBytes() bytes in C order and the array's byte order.
std::vector<std::byte> decodeZarrV3Chunk(const ZarrArrayMeta& meta,
                                         std::span<const std::byte> stored,
                                         const std::string& where);
// A Zarr v3 chunk whose storage applied its compressor (and checked its
// crc32c) already (ZarrStorage::decodesChunks): its size checked, then
// the transpose codec undone.
std::vector<std::byte> decodedZarrV3Chunk(const ZarrArrayMeta& meta, std::vector<std::byte> raw,
                                          const std::string& where);
}  // namespace io_detail
}  // namespace tessera
