// PVM3 output (ddsbase.cpp's writePVMvolume layout, uncompressed).
#include "tessera/io/PvmWriter.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <string>
#include <vector>

#include "io/OutputFile.h"
#include "io/PvmDds.h"
#include "tessera/core/Error.h"
#include "tessera/io/VolumeWriter.h"

namespace tessera {

namespace {

// Shortest text that reads back as the same double.
std::string shortestNumber(double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, ec == std::errc() ? end : buf);
}

std::string withoutNul(std::string s) {
  s.erase(std::remove(s.begin(), s.end(), '\0'), s.end());
  return s;
}

}  // namespace

void writePvm(const Volume& volume, const std::filesystem::path& path) {
  const std::string p = path.string();
  if (volume.type() != ScalarType::U8 && volume.type() != ScalarType::U16) {
    throw InputError(p + ": PVM stores only u8/u16 voxels, this volume is " +
                     std::string(scalarTypeName(volume.type())) +
                     "; write NRRD, NIfTI or raw + JSON instead");
  }
  if (!volume.hasData()) throw InputError(p + ": cannot write a volume without voxels");
  const glm::ivec3 d = volume.dims();
  const glm::dvec3 s = volume.spacing();
  const glm::dvec3 o = volume.origin();
  const int components = volume.type() == ScalarType::U8 ? 1 : 2;
  const std::string header = "PVM3\n" + std::to_string(d.x) + " " + std::to_string(d.y) + " " +
                             std::to_string(d.z) + "\n" + shortestNumber(s.x) + " " +
                             shortestNumber(s.y) + " " + shortestNumber(s.z) + "\n" +
                             std::to_string(components) + "\n";

  writeAtomically(path, [&](const std::filesystem::path& temp) {
    io_detail::OutputFile out(temp);
    out.write(header);
    const std::span<const std::byte> bytes = volume.bytes();
    if (components == 1 || std::endian::native == std::endian::big) {
      out.write(bytes.data(), bytes.size());
    } else {
      std::vector<std::byte> chunk;
      constexpr std::size_t kChunk = 1 << 20;
      for (std::size_t at = 0; at < bytes.size(); at += kChunk) {
        const std::size_t n = std::min(kChunk, bytes.size() - at);
        chunk.assign(bytes.begin() + static_cast<std::ptrdiff_t>(at),
                     bytes.begin() + static_cast<std::ptrdiff_t>(at + n));
        for (std::size_t i = 0; i + 1 < n; i += 2) std::swap(chunk[i], chunk[i + 1]);
        out.write(chunk.data(), n);
      }
    }
    // description, courtesy, parameter, comment: each zero-terminated.
    std::string trailer = withoutNul(volume.description());
    trailer += '\0';
    trailer += '\0';
    trailer += '\0';
    trailer += std::string(io_detail::kPvmOriginTag) + shortestNumber(o.x) + " " +
               shortestNumber(o.y) + " " + shortestNumber(o.z);
    trailer += '\0';
    out.write(trailer);
    out.close();
  });
}

}  // namespace tessera
