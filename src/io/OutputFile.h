#pragma once
// What the writers share: a file opened for writing whose every failure is
// an Error naming it, and the voxels in little-endian order, chunk by chunk.
// Writers write the path they are given; writeAtomically (VolumeWriter.h)
// makes that path a temporary file renamed into place once complete.
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "tessera/core/Volume.h"

namespace tessera::io_detail {

class OutputFile {
 public:
  explicit OutputFile(const std::filesystem::path& path);
  void write(const void* data, std::size_t n);
  void write(const std::string& s) { write(s.data(), s.size()); }
  std::streampos position();
  void seek(std::streampos pos);
  void close();
  const std::filesystem::path& path() const { return path_; }

 private:
  [[noreturn]] void fail(const char* what) const;
  std::filesystem::path path_;
  std::ofstream out_;
};

// `v` with 17 significant digits, so that it reads back as the same double
// ("%.17g"); -0 is written as 0.
std::string exactNumber(double v);

// Calls `sink(bytes, n)` with the volume's voxels in little-endian order,
// in chunks of at most 1 MiB (swapped copies on big-endian hosts).
void forEachLittleEndianChunk(const Volume& v,
                              const std::function<void(const std::byte*, std::size_t)>& sink);

}  // namespace tessera::io_detail
