#include "io/OutputFile.h"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <vector>

#include "tessera/core/Error.h"

namespace tessera::io_detail {

OutputFile::OutputFile(const std::filesystem::path& path)
    : path_(path), out_(path, std::ios::binary) {
  if (!out_) fail("cannot open for writing");
}

void OutputFile::write(const void* data, std::size_t n) {
  out_.write(static_cast<const char*>(data), static_cast<std::streamsize>(n));
  if (!out_) fail("write failed");
}

std::streampos OutputFile::position() {
  return out_.tellp();
}

void OutputFile::seek(std::streampos pos) {
  out_.seekp(pos);
  if (!out_) fail("seek failed");
}

void OutputFile::close() {
  out_.close();
  if (!out_) fail("write failed");
}

void OutputFile::fail(const char* what) const {
  throw Error(path_.string() + ": " + what + ": " + std::strerror(errno));
}

std::string exactNumber(double v) {
  char buf[40];
  // + 0.0 turns -0 (from negating a 0 into LPS) into 0.
  std::snprintf(buf, sizeof buf, "%.17g", v + 0.0);
  return buf;
}

void forEachLittleEndianChunk(const Volume& v,
                              const std::function<void(const std::byte*, std::size_t)>& sink) {
  const std::span<const std::byte> bytes = v.bytes();
  const std::size_t elem = bytesPerVoxel(v.type());
  constexpr std::size_t kChunk = 1 << 20;
  std::vector<std::byte> swapped;
  for (std::size_t at = 0; at < bytes.size(); at += kChunk) {
    const std::size_t n = std::min(kChunk, bytes.size() - at);
    const std::byte* chunk = bytes.data() + at;
    if (std::endian::native == std::endian::big && elem > 1) {
      swapped.assign(chunk, chunk + n);
      for (std::size_t i = 0; i + elem <= n; i += elem) {
        std::reverse(swapped.begin() + static_cast<std::ptrdiff_t>(i),
                     swapped.begin() + static_cast<std::ptrdiff_t>(i + elem));
      }
      chunk = swapped.data();
    }
    sink(chunk, n);
  }
}

}  // namespace tessera::io_detail
