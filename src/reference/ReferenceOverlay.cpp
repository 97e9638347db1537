#include "tessera/reference/ReferenceOverlay.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <thread>

#include <glm/common.hpp>

#include "tessera/core/Error.h"
#include "tessera/reference/ReferenceRaycaster.h"

namespace tessera {

namespace {

// The same reconstruction as sampleTrilinear(), over values converted to
// double once (the per-voxel type switch would dominate a full-size frame).
std::vector<double> toDoubles(const Volume& v) {
  std::vector<double> out(static_cast<std::size_t>(v.voxelCount()));
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double s = v.valueAtIndex(i);
    out[i] = std::isfinite(s) ? s : 0.0;
  }
  return out;
}

double trilinear(const std::vector<double>& data, glm::ivec3 d, glm::dvec3 p) {
  const glm::dvec3 u = p * glm::dvec3(d) - 0.5;
  const glm::dvec3 f = glm::floor(u);
  const glm::dvec3 w = u - f;
  const glm::ivec3 i0 = glm::clamp(glm::ivec3(f), glm::ivec3(0), d - 1);
  const glm::ivec3 i1 = glm::clamp(glm::ivec3(f) + 1, glm::ivec3(0), d - 1);
  auto at = [&](int x, int y, int z) {
    return data[(static_cast<std::size_t>(z) * d.y + y) * d.x + x];
  };
  const double c00 = at(i0.x, i0.y, i0.z) * (1 - w.x) + at(i1.x, i0.y, i0.z) * w.x;
  const double c10 = at(i0.x, i1.y, i0.z) * (1 - w.x) + at(i1.x, i1.y, i0.z) * w.x;
  const double c01 = at(i0.x, i0.y, i1.z) * (1 - w.x) + at(i1.x, i0.y, i1.z) * w.x;
  const double c11 = at(i0.x, i1.y, i1.z) * (1 - w.x) + at(i1.x, i1.y, i1.z) * w.x;
  return (c00 * (1 - w.y) + c10 * w.y) * (1 - w.z) + (c01 * (1 - w.y) + c11 * w.y) * w.z;
}

std::uint8_t toByte(double v) {
  return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
}

}  // namespace

Image renderReferenceWithLines(const Volume& volume, const TransferFunction& tf,
                               const Camera& camera, const RenderSettings& settings, int width,
                               int height, const Image& lineColor,
                               const std::vector<float>& lineDistance, int threads) {
  if (width <= 0 || height <= 0) throw InputError("reference: image size must be positive");
  if (!(settings.stepVoxels > 0.0)) throw InputError("reference: step must be > 0");
  if (lineColor.width() != width || lineColor.height() != height ||
      lineDistance.size() != static_cast<std::size_t>(width) * height) {
    throw InputError("reference overlay: line layer is " + std::to_string(lineColor.width()) + "x" +
                     std::to_string(lineColor.height()) + " with " +
                     std::to_string(lineDistance.size()) + " distances, image is " +
                     std::to_string(width) + "x" + std::to_string(height));
  }
  if (settings.mode != RenderMode::Composite) {
    throw InputError("reference overlay: only composite mode attenuates lines");
  }
  const std::vector<double> data = toDoubles(volume);
  const glm::ivec3 dims = volume.dims();
  const glm::dvec3 extent = volume.extent();
  const glm::dvec3 spacing = volume.spacing();
  const double ds = settings.stepVoxels * std::min({spacing.x, spacing.y, spacing.z});
  const ValueRange win = volume.window();
  const double ww = win.max - win.min;
  const glm::dvec4 bg = settings.background;

  Image image(width, height);
  std::atomic<int> nextRow{0};
  auto worker = [&] {
    for (int py = nextRow++; py < height; py = nextRow++) {
      for (int px = 0; px < width; ++px) {
        const std::size_t index = static_cast<std::size_t>(py) * width + px;
        const bool hasLine = lineColor.pixel(px, py)[3] > 0;
        const double tLine = hasLine ? static_cast<double>(lineDistance[index])
                                     : std::numeric_limits<double>::infinity();
        const Ray ray = camera.pixelRay(px, py, width, height);
        const glm::dvec3 to = ray.origin / extent + 0.5;
        const glm::dvec3 td = ray.direction / extent;
        double tNear = -std::numeric_limits<double>::infinity();
        double tFar = std::numeric_limits<double>::infinity();
        for (int a = 0; a < 3; ++a) {
          if (td[a] == 0.0) {
            if (to[a] < 0.0 || to[a] > 1.0) tNear = std::numeric_limits<double>::infinity();
            continue;
          }
          const double t0 = (0.0 - to[a]) / td[a], t1 = (1.0 - to[a]) / td[a];
          tNear = std::max(tNear, std::min(t0, t1));
          tFar = std::min(tFar, std::max(t0, t1));
        }
        const double t0 = std::max(tNear, 0.0);
        // The ray stops where it meets the line: only the volume in front of
        // the line is composited.
        const double tEnd = std::min(tFar, tLine);
        glm::dvec4 acc(0.0);
        if (t0 < tEnd) {
          const double j = settings.jitter
                               ? jitterOffset(static_cast<unsigned>(px), static_cast<unsigned>(py))
                               : 0.5;
          for (int k = 0; k < settings.maxSteps; ++k) {
            const double t = t0 + (k + j) * ds;
            if (t >= tEnd) break;
            const double raw = trilinear(data, dims, to + t * td);
            const double n = std::clamp((raw - win.min) / ww, 0.0, 1.0);
            const glm::dvec3 c = tf.color(n);
            const double a = tf.correctedOpacity(n, ds, settings.opacityScale);
            acc += (1.0 - acc.a) * glm::dvec4(c * a, a);
            if (acc.a >= settings.ertThreshold) break;
          }
        }
        glm::dvec4 under = bg;
        if (hasLine) {
          const std::uint8_t* l = lineColor.pixel(px, py);
          under = glm::dvec4(l[0] / 255.0, l[1] / 255.0, l[2] / 255.0, 1.0);
        }
        const glm::dvec4 out(glm::dvec3(acc) + (1.0 - acc.a) * glm::dvec3(under),
                             acc.a + (1.0 - acc.a) * under.a);
        std::uint8_t* pix = image.pixel(px, py);
        for (int ch = 0; ch < 4; ++ch) pix[ch] = toByte(out[ch]);
      }
    }
  };
  const int n =
      threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::vector<std::thread> pool;
  for (int i = 0; i < n; ++i) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  return image;
}

}  // namespace tessera
