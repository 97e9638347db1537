#include "tessera/layout/ValueBlocks.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <thread>
#include <utility>

#include <glm/common.hpp>

#include "tessera/core/Error.h"

namespace tessera::layout {

namespace {
template <class T>
void blockRange(const Volume& v, const T* data, glm::ivec3 lo, glm::ivec3 hi, float& mn,
                float& mx) {
  // Only f32 has NaN/Inf; they render as the bottom of the range.
  const float missing = static_cast<float>(v.nonFiniteValue());
  const glm::ivec3 d = v.dims();
  float a = std::numeric_limits<float>::infinity();
  float b = -a;
  for (int z = lo.z; z <= hi.z; ++z) {
    for (int y = lo.y; y <= hi.y; ++y) {
      const T* row = data + (static_cast<std::size_t>(z) * d.y + y) * d.x;
      for (int x = lo.x; x <= hi.x; ++x) {
        float s = static_cast<float>(row[x]);
        if (!std::isfinite(s)) s = missing;
        if (s < a) a = s;
        if (s > b) b = s;
      }
    }
  }
  mn = a;
  mx = b;
}
}  // namespace

ValueBlocks::ValueBlocks(glm::ivec3 count, int blockSize, int supportVoxels,
                         std::vector<float> mins, std::vector<float> maxs)
    : blockSize_(blockSize),
      support_(supportVoxels),
      count_(count),
      min_(std::move(mins)),
      max_(std::move(maxs)) {
  const std::size_t n = static_cast<std::size_t>(count.x) * count.y * count.z;
  if (min_.size() != n || max_.size() != n) {
    throw Error("value blocks: " + std::to_string(n) + " blocks, " + std::to_string(min_.size()) +
                " minima and " + std::to_string(max_.size()) + " maxima given");
  }
}

ValueBlocks::ValueBlocks(const Volume& volume, int blockSize, int supportVoxels)
    : blockSize_(blockSize), support_(supportVoxels) {
  const glm::ivec3 d = volume.dims();
  count_ = (d + blockSize - 1) / blockSize;
  const std::size_t n = static_cast<std::size_t>(count_.x) * count_.y * count_.z;
  min_.assign(n, 0.0f);
  max_.assign(n, 0.0f);
  auto work = [&](int zBegin, int zEnd) {
    for (int bz = zBegin; bz < zEnd; ++bz) {
      for (int by = 0; by < count_.y; ++by) {
        for (int bx = 0; bx < count_.x; ++bx) {
          const glm::ivec3 b(bx, by, bz);
          const glm::ivec3 lo = glm::max(b * blockSize - supportVoxels, glm::ivec3(0));
          const glm::ivec3 hi = glm::min((b + 1) * blockSize + supportVoxels - 1, d - 1);
          float mn = 0, mx = 0;
          switch (volume.type()) {
            case ScalarType::U8:
              blockRange(volume, volume.dataAs<std::uint8_t>(), lo, hi, mn, mx);
              break;
            case ScalarType::U16:
              blockRange(volume, volume.dataAs<std::uint16_t>(), lo, hi, mn, mx);
              break;
            case ScalarType::I16:
              blockRange(volume, volume.dataAs<std::int16_t>(), lo, hi, mn, mx);
              break;
            case ScalarType::F32:
              blockRange(volume, volume.dataAs<float>(), lo, hi, mn, mx);
              break;
          }
          min_[index(bx, by, bz)] = mn;
          max_[index(bx, by, bz)] = mx;
        }
      }
    }
  };
  const int threads = std::max(1u, std::min(8u, std::thread::hardware_concurrency()));
  std::vector<std::thread> pool;
  const int per = (count_.z + threads - 1) / threads;
  for (int t = 0; t < threads; ++t) {
    const int z0 = t * per, z1 = std::min(count_.z, z0 + per);
    // One thread: run here (the web build cannot start threads at all).
    if (z0 < z1 && threads == 1) work(z0, z1);
    if (z0 < z1 && threads > 1) pool.emplace_back(work, z0, z1);
  }
  for (auto& th : pool) th.join();
}

}  // namespace tessera::layout
