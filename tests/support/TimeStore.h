#pragma once
// A generated OME-Zarr store with a t axis (and optionally a c axis): 64^3
// u8 per time point, a dim smooth sphere shell and a bright 8^3 cube whose
// x (channel 0), y (channel 1) or z (channel 2) position moves with t, so that each time
// point renders differently and a frame shows which one it is. NGFF 0.4 on
// Zarr v2, uncompressed 32^3 chunks written byte by byte, two levels (the
// second the 2x2x2 mean), an omero window 0..255.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace tessera::test {

inline constexpr int kTimeStoreSide = 64;
inline constexpr int kTimeStoreChunk = 32;

inline void writeTimeStoreText(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

// Whether voxel (x, y, z) lies in channel c's bright 8^3 cube at time t:
// moving along x (channel 0), y (1) or z (2), centred on the other axes.
inline bool inTimeStoreCube(int x, int y, int z, int t, int c) {
  const int p[3] = {x, y, z};
  const int moving = c % 3;
  const int m = 8 + 10 * t;  // the moving axis's first voxel
  bool in = p[moving] >= m && p[moving] < m + 8;
  for (int k = 0; k < 3; ++k) {
    if (k != moving) in = in && p[k] >= 28 && p[k] < 36;
  }
  return in;
}

// Voxel (x, y, z) of channel c at time t: a dim smooth sphere shell and
// the channel's bright cube.
inline std::uint8_t timeStoreVoxel(int x, int y, int z, int t, int c) {
  const double r =
      std::sqrt((x - 31.5) * (x - 31.5) + (y - 31.5) * (y - 31.5) + (z - 31.5) * (z - 31.5)) - 24.0;
  double v = 50.0 * std::exp(-(r / 2.0) * (r / 2.0));
  if (inTimeStoreCube(x, y, z, t, c)) v = 220.0;
  return static_cast<std::uint8_t>(std::lround(v));
}

// NGFF 0.4 on Zarr v2, uncompressed: level 0 (64^3, 32^3 chunks) and
// level 1 (its 2x2x2 mean), axes t[, c], z, y, x, an omero window 0..255.
inline std::filesystem::path writeTimeStore(const std::filesystem::path& dir, int times,
                                            int channels) {
  const auto root = dir / (channels > 1 ? "tc.ome.zarr" : "t.ome.zarr");
  const bool hasC = channels > 1;
  writeTimeStoreText(root / ".zgroup", R"({"zarr_format": 2})");
  const std::string ones = hasC ? "1.0, 1.0, " : "1.0, ";
  std::string omero;
  for (int c = 0; c < channels; ++c) {
    omero += std::string(c ? ", " : "") + R"({"label": "ch)" + std::to_string(c) +
             R"(", "color": ")" +
             (c == 0   ? "FF00FF"
              : c == 1 ? "00FF00"
                       : "0080FF") +
             R"(", "active": true, "window": {"start": 0, "end": 255, "min": 0, "max": 255}})";
  }
  writeTimeStoreText(
      root / ".zattrs",
      std::string(R"({"multiscales": [{"version": "0.4", "type": "mean", "axes": [)") +
          R"({"name": "t", "type": "time"}, )" +
          (hasC ? R"({"name": "c", "type": "channel"}, )" : "") +
          R"({"name": "z", "type": "space", "unit": "millimeter"},)" +
          R"({"name": "y", "type": "space", "unit": "millimeter"},)" +
          R"({"name": "x", "type": "space", "unit": "millimeter"}], "datasets": [)" +
          R"({"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [)" + ones +
          R"(1.0, 1.0, 1.0]}]},)" +
          R"({"path": "1", "coordinateTransformations": [{"type": "scale", "scale": [)" + ones +
          R"(2.0, 2.0, 2.0]}, {"type": "translation", "translation": [)" +
          (hasC ? "0.0, 0.0, " : "0.0, ") + R"(0.5, 0.5, 0.5]}]}]}], )" +
          R"("omero": {"channels": [)" + omero + "]}}");
  for (int level = 0; level < 2; ++level) {
    const int n = kTimeStoreSide >> level;
    const std::string lead =
        std::to_string(times) + ", " + (hasC ? std::to_string(channels) + ", " : "");
    const std::string chunkLead = hasC ? "1, 1, " : "1, ";
    writeTimeStoreText(
        root / std::to_string(level) / ".zarray",
        R"({"zarr_format": 2, "shape": [)" + lead + std::to_string(n) + ", " + std::to_string(n) +
            ", " + std::to_string(n) + R"(], "chunks": [)" + chunkLead + "32, 32, 32" +
            R"(], "dtype": "|u1", "compressor": null, "fill_value": 0, "order": "C", "filters": null})");
    for (int t = 0; t < times; ++t) {
      for (int c = 0; c < channels; ++c) {
        for (int cz = 0; cz < n / kTimeStoreChunk; ++cz) {
          for (int cy = 0; cy < n / kTimeStoreChunk; ++cy) {
            for (int cx = 0; cx < n / kTimeStoreChunk; ++cx) {
              std::string bytes(kTimeStoreChunk * kTimeStoreChunk * kTimeStoreChunk, '\0');
              for (int z = 0; z < kTimeStoreChunk; ++z) {
                for (int y = 0; y < kTimeStoreChunk; ++y) {
                  for (int x = 0; x < kTimeStoreChunk; ++x) {
                    const int gx = cx * kTimeStoreChunk + x, gy = cy * kTimeStoreChunk + y,
                              gz = cz * kTimeStoreChunk + z;
                    int v = 0;
                    if (level == 0) {
                      v = timeStoreVoxel(gx, gy, gz, t, c);
                    } else {
                      for (int k = 0; k < 8; ++k) {
                        v += timeStoreVoxel(2 * gx + (k & 1), 2 * gy + (k >> 1 & 1),
                                            2 * gz + (k >> 2), t, c);
                      }
                      v = (v + 4) / 8;
                    }
                    bytes[static_cast<std::size_t>((z * kTimeStoreChunk + y) * kTimeStoreChunk +
                                                   x)] = static_cast<char>(v);
                  }
                }
              }
              const std::string key = std::to_string(t) + "." +
                                      (hasC ? std::to_string(c) + "." : "") + std::to_string(cz) +
                                      "." + std::to_string(cy) + "." + std::to_string(cx);
              writeTimeStoreText(root / std::to_string(level) / key, bytes);
            }
          }
        }
      }
    }
  }
  return root;
}

}  // namespace tessera::test
