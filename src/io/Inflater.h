#pragma once
// The seam between the readers and the deflate codec: one zlib (RFC 1950) or
// gzip (RFC 1952) stream, told apart by its header, inflated piece by piece
// into the caller's buffer. Native builds use zlib (io/InflaterZlib.cpp);
// the browser, which has no zlib, the page's pako through JavaScript
// (frontends/web/src/InflaterPako.cpp). Both run behind the same readers, so their
// chunked, budget-checked decoding is the same everywhere.
#include <cstddef>
#include <memory>
#include <span>
#include <string>

namespace tessera::io_detail {

class Inflater {
 public:
  struct Step {
    std::size_t consumed = 0;  // input bytes used
    std::size_t produced = 0;  // bytes written to the output
    bool ended = false;        // the stream, with its checksum, is complete
    std::string error;         // the codec's words for corrupt data; then nothing else counts
  };

  // A new inflater, for one stream; defined once per platform.
  static std::unique_ptr<Inflater> create();
  virtual ~Inflater() = default;

  // Inflates from `in` into `out`. A step that consumes and produces nothing
  // needs more input (or more room); after `ended` the inflater is spent.
  virtual Step inflate(std::span<const std::byte> in, std::span<std::byte> out) = 0;
};

}  // namespace tessera::io_detail
