// The browser's Zarr chunk decoders (io/ZarrCodecs.h): zlib and gzip
// through the page's pako (io/Inflater.h, frontends/web/src/InflaterPako.cpp), with
// the same checks as the native decoder's. Debian's libzstd and libblosc
// cannot be linked by emscripten here: zstd and blosc chunks are decoded by
// the page before they arrive (frontends/web/zarr-url.js, numcodecs' WebAssembly
// builds of the same libraries) when it can load them; a chunk that still
// reaches these decoders is an error naming the chunk's URL and the codec.
#include <algorithm>

#include "io/Inflater.h"
#include "io/ZarrCodecs.h"
#include "tessera/core/Error.h"

namespace tessera::io_detail {

std::vector<std::byte> inflateZarrChunk(std::span<const std::byte> in, std::uint64_t expected,
                                        bool gzip, const std::string& where) {
  const char* codec = gzip ? "gzip" : "zlib";
  std::vector<std::byte> out(expected);
  const std::unique_ptr<Inflater> inflater = Inflater::create();
  std::size_t used = 0, produced = 0;
  while (true) {
    const Inflater::Step s = inflater->inflate(in.subspan(used), std::span(out).subspan(produced));
    used += s.consumed;
    produced += s.produced;
    if (!s.error.empty()) throw InputError(where + ": corrupt " + codec + " chunk: " + s.error);
    if (s.ended) break;
    if (s.consumed == 0 && s.produced == 0) {
      if (produced == out.size()) {
        throw InputError(where + ": " + codec + " chunk decompresses to more than the expected " +
                         std::to_string(expected) + " bytes");
      }
      throw InputError(where + ": truncated " + codec + " chunk (" + std::to_string(in.size()) +
                       " bytes stored, stream ends after " + std::to_string(produced) + " of " +
                       std::to_string(expected) + " bytes)");
    }
  }
  if (produced != expected) {
    throw InputError(where + ": " + codec + " chunk decompressed to " + std::to_string(produced) +
                     " bytes, expected " + std::to_string(expected));
  }
  return out;
}

namespace {

[[noreturn]] void notInThisBuild(const char* codec, const std::string& where) {
  throw InputError(where + ": " + codec +
                   " chunks cannot be decoded in this page: the browser build has no " + codec +
                   " decoder of its own (Debian's library is native only) and the page did not "
                   "decode the chunk before it arrived (numcodecs not loaded)");
}

}  // namespace

std::vector<std::byte> zstdZarrChunk(std::span<const std::byte>, std::uint64_t,
                                     const std::string& where) {
  notInThisBuild("zstd", where);
}

std::vector<std::byte> bloscZarrChunk(std::span<const std::byte>, std::uint64_t,
                                      const std::string& where) {
  notInThisBuild("blosc", where);
}

}  // namespace tessera::io_detail
