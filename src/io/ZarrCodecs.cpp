// Zarr chunk codecs of the native build (io/ZarrCodecs.h): numcodecs'
// zlib, gzip, zstd and blosc through Debian's zlib, libzstd and libblosc.
// The browser build has its own (frontends/web/src/ZarrCodecsWeb.cpp).
#include "io/ZarrCodecs.h"

#include <blosc.h>
#include <zlib.h>
#include <zstd.h>

#include "tessera/core/Error.h"
#include "tessera/io/ZarrArray.h"

namespace tessera {

namespace io_detail {

std::vector<std::byte> inflateZarrChunk(std::span<const std::byte> in, std::uint64_t expected,
                                        bool gzip, const std::string& where) {
  std::vector<std::byte> out(expected);
  z_stream zs{};
  if (inflateInit2(&zs, gzip ? 15 + 16 : 15) != Z_OK) {
    throw Error(where + ": zlib inflateInit failed");
  }
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(in.data()));
  zs.avail_in = static_cast<uInt>(in.size());
  zs.next_out = reinterpret_cast<Bytef*>(out.data());
  zs.avail_out = static_cast<uInt>(out.size());
  const int ret = inflate(&zs, Z_FINISH);
  const std::uint64_t produced = zs.total_out;
  const char* msg = zs.msg;
  const std::string reason = msg ? msg : "";
  inflateEnd(&zs);
  const char* codec = gzip ? "gzip" : "zlib";
  if (ret == Z_STREAM_END && produced == expected) return out;
  if (ret == Z_STREAM_END) {
    throw InputError(where + ": " + codec + " chunk decompressed to " + std::to_string(produced) +
                     " bytes, expected " + std::to_string(expected));
  }
  if (ret == Z_BUF_ERROR && zs.avail_out == 0) {
    throw InputError(where + ": " + codec + " chunk decompresses to more than the expected " +
                     std::to_string(expected) + " bytes");
  }
  if (ret == Z_BUF_ERROR) {
    throw InputError(where + ": truncated " + codec + " chunk (" + std::to_string(in.size()) +
                     " bytes stored, stream ends after " + std::to_string(produced) + " of " +
                     std::to_string(expected) + " bytes)");
  }
  throw InputError(where + ": corrupt " + codec + " chunk" + (reason.empty() ? "" : ": " + reason));
}

std::vector<std::byte> zstdZarrChunk(std::span<const std::byte> in, std::uint64_t expected,
                                     const std::string& where) {
  const unsigned long long declared = ZSTD_getFrameContentSize(in.data(), in.size());
  if (declared == ZSTD_CONTENTSIZE_ERROR) {
    throw InputError(where + ": not a zstd frame (corrupt or truncated chunk)");
  }
  if (declared != ZSTD_CONTENTSIZE_UNKNOWN && declared != expected) {
    throw InputError(where + ": zstd chunk declares " + std::to_string(declared) +
                     " bytes, expected " + std::to_string(expected));
  }
  std::vector<std::byte> out(expected);
  const std::size_t n = ZSTD_decompress(out.data(), out.size(), in.data(), in.size());
  if (ZSTD_isError(n)) {
    throw InputError(where + ": corrupt or truncated zstd chunk (" + ZSTD_getErrorName(n) + ")");
  }
  if (n != expected) {
    throw InputError(where + ": zstd chunk decompressed to " + std::to_string(n) +
                     " bytes, expected " + std::to_string(expected));
  }
  return out;
}

std::vector<std::byte> bloscZarrChunk(std::span<const std::byte> in, std::uint64_t expected,
                                      const std::string& where) {
  if (in.size() < BLOSC_MIN_HEADER_LENGTH) {
    throw InputError(where + ": truncated blosc chunk (" + std::to_string(in.size()) +
                     " bytes, shorter than the 16-byte header)");
  }
  std::size_t nbytes = 0, cbytes = 0, blocksize = 0;
  blosc_cbuffer_sizes(in.data(), &nbytes, &cbytes, &blocksize);
  if (cbytes != in.size()) {
    throw InputError(where + ": blosc header says " + std::to_string(cbytes) +
                     " compressed bytes, the chunk has " + std::to_string(in.size()) +
                     (cbytes > in.size() ? " (truncated)" : ""));
  }
  if (nbytes != expected) {
    throw InputError(where + ": blosc chunk holds " + std::to_string(nbytes) + " bytes, expected " +
                     std::to_string(expected));
  }
  std::size_t validated = 0;
  if (blosc_cbuffer_validate(in.data(), in.size(), &validated) != 0 || validated != expected) {
    throw InputError(where + ": corrupt blosc header");
  }
  std::vector<std::byte> out(expected);
  const int n = blosc_decompress_ctx(in.data(), out.data(), out.size(), 1);
  if (n < 0 || std::uint64_t(n) != expected) {
    throw InputError(where + ": corrupt blosc chunk (blosc_decompress returned " +
                     std::to_string(n) + ")");
  }
  return out;
}

}  // namespace io_detail

namespace {

std::vector<std::byte> deflateChunk(std::span<const std::byte> raw, bool gzip) {
  z_stream zs{};
  if (deflateInit2(&zs, 6, Z_DEFLATED, gzip ? 15 + 16 : 15, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
    throw Error("zlib deflateInit failed");
  }
  std::vector<std::byte> out(deflateBound(&zs, static_cast<uLong>(raw.size())) + 32);
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(raw.data()));
  zs.avail_in = static_cast<uInt>(raw.size());
  zs.next_out = reinterpret_cast<Bytef*>(out.data());
  zs.avail_out = static_cast<uInt>(out.size());
  const int ret = deflate(&zs, Z_FINISH);
  out.resize(zs.total_out);
  deflateEnd(&zs);
  if (ret != Z_STREAM_END) throw Error("zlib deflate failed");
  return out;
}

}  // namespace

std::vector<std::byte> encodeZarrChunk(ZarrCompressor compressor, int itemSize,
                                       std::span<const std::byte> raw) {
  switch (compressor) {
    case ZarrCompressor::None:
      return {raw.begin(), raw.end()};
    case ZarrCompressor::Zlib:
      return deflateChunk(raw, false);
    case ZarrCompressor::Gzip:
      return deflateChunk(raw, true);
    case ZarrCompressor::Zstd: {
      std::vector<std::byte> out(ZSTD_compressBound(raw.size()));
      const std::size_t n = ZSTD_compress(out.data(), out.size(), raw.data(), raw.size(), 3);
      if (ZSTD_isError(n)) throw Error(std::string("zstd: ") + ZSTD_getErrorName(n));
      out.resize(n);
      return out;
    }
    case ZarrCompressor::Blosc: {
      std::vector<std::byte> out(raw.size() + BLOSC_MAX_OVERHEAD);
      const int n =
          blosc_compress_ctx(5, BLOSC_SHUFFLE, static_cast<std::size_t>(itemSize), raw.size(),
                             raw.data(), out.data(), out.size(), BLOSC_LZ4_COMPNAME, 0, 1);
      if (n <= 0) throw Error("blosc_compress failed (" + std::to_string(n) + ")");
      out.resize(static_cast<std::size_t>(n));
      return out;
    }
  }
  throw Error("unknown compressor");
}

}  // namespace tessera
