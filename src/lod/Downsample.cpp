#include "tessera/lod/Downsample.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>
#include <vector>

#include "tessera/core/Error.h"

namespace tessera::lod {

Volume downsample(const Volume& volume, glm::ivec3 factor) {
  if (factor.x < 1 || factor.y < 1 || factor.z < 1) {
    throw InputError("downsample factors must be >= 1");
  }
  const glm::ivec3 d = volume.dims();
  const glm::ivec3 out = (d + factor - 1) / factor;
  Volume result = Volume::allocate(out, volume.type(), "downsampled volume");
  result.setSpacing(volume.spacing() * glm::dvec3(factor));
  result.setDirection(volume.direction());
  // An output voxel averages `factor` input voxels, so its centre lies
  // (factor - 1) / 2 input voxels past the first of them.
  result.setOrigin(volume.worldOf(0.5 * (glm::dvec3(factor) - 1.0)));
  result.setGeometrySource(volume.geometrySource());
  if (volume.hasWindow()) result.setWindow(volume.window());
  result.setDescription(volume.description() + " (downsampled " + std::to_string(factor.x) + "x" +
                        std::to_string(factor.y) + "x" + std::to_string(factor.z) + ")");
  auto work = [&](int z0, int z1) {
    for (int oz = z0; oz < z1; ++oz) {
      for (int oy = 0; oy < out.y; ++oy) {
        for (int ox = 0; ox < out.x; ++ox) {
          double sum = 0.0;
          int n = 0;
          for (int z = oz * factor.z; z < std::min(d.z, (oz + 1) * factor.z); ++z) {
            for (int y = oy * factor.y; y < std::min(d.y, (oy + 1) * factor.y); ++y) {
              for (int x = ox * factor.x; x < std::min(d.x, (ox + 1) * factor.x); ++x) {
                const double v = volume.valueAt(x, y, z);
                if (std::isfinite(v)) {
                  sum += v;
                  ++n;
                }
              }
            }
          }
          // Integer types round to nearest (setValueAtIndex clamps and rounds).
          // A block of only NaN stays missing data (NaN), not a real 0.
          result.setValueAtIndex(result.index(ox, oy, oz),
                                 n ? sum / n : std::numeric_limits<double>::quiet_NaN());
        }
      }
    }
  };
  const int threads =
      static_cast<int>(std::max(1u, std::min(8u, std::thread::hardware_concurrency())));
  std::vector<std::thread> pool;
  const int per = (out.z + threads - 1) / threads;
  for (int t = 0; t < threads; ++t) {
    const int z0 = t * per, z1 = std::min(out.z, z0 + per);
    // One thread: run here (the web build cannot start threads at all).
    if (z0 < z1 && threads == 1) work(z0, z1);
    if (z0 < z1 && threads > 1) pool.emplace_back(work, z0, z1);
  }
  for (auto& th : pool) th.join();
  result.invalidateRange();
  return result;
}

}  // namespace tessera::lod
