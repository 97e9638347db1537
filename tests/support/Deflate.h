#pragma once
// zlib's deflate for test inputs: gzip members (windowBits 15 + 16) and raw
// deflate streams (-15, DICOM's Deflated Explicit VR Little Endian).
#include <zlib.h>

#include <stdexcept>
#include <string>
#include <string_view>

namespace tessera::test {

inline std::string deflateBytes(std::string_view data, int windowBits, int level) {
  z_stream zs{};
  if (deflateInit2(&zs, level, Z_DEFLATED, windowBits, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
    throw std::runtime_error("deflateInit2 failed");
  }
  std::string out(deflateBound(&zs, static_cast<uLong>(data.size())) + 64, '\0');
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  zs.avail_in = static_cast<uInt>(data.size());
  zs.next_out = reinterpret_cast<Bytef*>(out.data());
  zs.avail_out = static_cast<uInt>(out.size());
  const int ret = deflate(&zs, Z_FINISH);
  out.resize(zs.total_out);
  deflateEnd(&zs);
  if (ret != Z_STREAM_END) throw std::runtime_error("deflate failed");
  return out;
}

}  // namespace tessera::test
