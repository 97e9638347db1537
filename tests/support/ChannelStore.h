#pragma once
// A small 3-channel u16 OME-Zarr store (NGFF 0.4 on Zarr v2, uncompressed
// chunks written byte by byte from the spec) with one known structure per
// channel: a sphere (channel 0), a slab (1) and a rod (2), each on a
// background of 100, and omero rendering metadata.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/core/Image.h"

namespace tessera::test {

struct ChannelStoreSpec {
  glm::ivec3 dims{96, 96, 48};
  bool thirdActive = true;
};

// Whether voxel (x, y, z) of a dims-sized grid lies in channel c's structure.
inline bool inChannelStructure(int c, glm::ivec3 d, int x, int y, int z) {
  const double fx = (x + 0.5) / d.x, fy = (y + 0.5) / d.y, fz = (z + 0.5) / d.z;
  if (c == 0) {  // sphere at (0.35, 0.4, 0.5), radius 0.22 of the box
    const double dx = fx - 0.35, dy = fy - 0.4, dz = fz - 0.5;
    return dx * dx + dy * dy + dz * dz < 0.22 * 0.22;
  }
  if (c == 1) return fy > 0.62 && fy < 0.78;  // slab across x and z
  const double dx = fx - 0.72, dz = fz - 0.45;
  return dx * dx + dz * dz < 0.08 * 0.08;  // rod along y
}

inline std::uint16_t channelStoreValue(int c, glm::ivec3 d, int x, int y, int z) {
  static const std::uint16_t inside[3] = {3000, 2000, 4000};
  return inChannelStructure(c, d, x, y, z) ? inside[c] : 100;
}

inline void writeChannelStore(const std::filesystem::path& dir, const ChannelStoreSpec& spec = {}) {
  namespace fs = std::filesystem;
  fs::remove_all(dir);
  fs::create_directories(dir / "0");
  const glm::ivec3 d = spec.dims;
  std::ofstream(dir / ".zgroup") << R"({"zarr_format": 2})";
  std::ofstream(dir / ".zattrs") << R"({"multiscales": [{"version": "0.4", "name": "channels",
  "axes": [{"name": "c", "type": "channel"}, {"name": "z", "type": "space", "unit": "millimeter"},
           {"name": "y", "type": "space", "unit": "millimeter"},
           {"name": "x", "type": "space", "unit": "millimeter"}],
  "datasets": [{"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1, 1, 1, 1]}]}]}],
 "omero": {"channels": [
  {"label": "sphere", "color": "FF0000", "active": true,
   "window": {"min": 100, "max": 3000, "start": 100, "end": 3000}},
  {"label": "slab", "color": "00FF00", "active": true,
   "window": {"min": 100, "max": 2000, "start": 50, "end": 2500}},
  {"label": "rod", "color": "0080FF", "active": )"
                                 << (spec.thirdActive ? "true" : "false") << R"(,
   "window": {"min": 100, "max": 4000, "start": 100, "end": 4000}}]}})";
  std::ofstream(dir / "0" / ".zarray")
      << R"({"zarr_format": 2, "shape": [3, )" << d.z << ", " << d.y << ", " << d.x
      << R"(], "chunks": [1, )" << d.z << ", " << d.y << ", " << d.x
      << R"(], "dtype": "<u2", "compressor": null, "fill_value": 0, "order": "C",
 "filters": null, "dimension_separator": "/"})";
  for (int c = 0; c < 3; ++c) {
    std::vector<std::uint8_t> bytes;
    bytes.reserve(static_cast<std::size_t>(d.x) * d.y * d.z * 2);
    for (int z = 0; z < d.z; ++z) {
      for (int y = 0; y < d.y; ++y) {
        for (int x = 0; x < d.x; ++x) {
          const std::uint16_t v = channelStoreValue(c, d, x, y, z);
          bytes.push_back(static_cast<std::uint8_t>(v & 0xff));
          bytes.push_back(static_cast<std::uint8_t>(v >> 8));
        }
      }
    }
    const fs::path chunk = dir / "0" / std::to_string(c) / "0" / "0";
    fs::create_directories(chunk);
    std::ofstream(chunk / "0", std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()),
               static_cast<std::streamsize>(bytes.size()));
  }
}

// Pixels where some colour component differs by more than `tol` levels:
// the footprint a toggled channel changed.
inline std::vector<bool> differing(const Image& a, const Image& b, int tol) {
  std::vector<bool> out(static_cast<std::size_t>(a.width()) * a.height(), false);
  for (std::size_t p = 0; p < out.size(); ++p) {
    for (int k = 0; k < 3; ++k) {
      if (std::abs(int(a.rgba()[4 * p + k]) - int(b.rgba()[4 * p + k])) > tol) out[p] = true;
    }
  }
  return out;
}

}  // namespace tessera::test
