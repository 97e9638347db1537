#include "tessera/reference/ChannelReference.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <thread>
#include <vector>

#include "tessera/core/Error.h"
#include "tessera/reference/ReferenceRaycaster.h"

namespace tessera {

namespace {

std::uint8_t toByte(double v) {
  return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
}

using ChannelValues = std::array<double, ChannelSet::kMaxChannels>;

// Channel i's raw value at p: its own volume's trilinear field, or with
// `levels` the level p's cell shows.
double rawAt(const ChannelSet& set, const ChannelLevels* levels, int i, glm::dvec3 p) {
  if (!levels) return sampleTrilinear(*set[i].volume, p);
  const auto l = static_cast<std::size_t>(levels->cells.levelAt(p));
  return sampleLevel(*levels->volumes[static_cast<std::size_t>(i)][l], levels->scales[l],
                     levels->cells.finestDims, p);
}

// n_i = clamp((v_i - lo_i) / (hi_i - lo_i), 0, 1); 0 for a hidden channel.
ChannelValues normalisedAt(const ChannelSet& set, const ChannelLevels* levels, glm::dvec3 p) {
  ChannelValues n{};
  for (int i = 0; i < set.size(); ++i) {
    const Channel& c = set[i];
    if (!c.visible) continue;
    n[static_cast<std::size_t>(i)] = std::clamp(
        (rawAt(set, levels, i, p) - c.window.min) / (c.window.max - c.window.min), 0.0, 1.0);
  }
  return n;
}

// Every cell's level is held for every channel.
void checkLevels(const ChannelSet& set, const ChannelLevels& levels) {
  const std::vector<int> n = levels.cells.cellsPerLevel();
  if (n.back() > 0) {
    throw InputError("channel reference: " + std::to_string(n.back()) +
                     " cells are transparent constants, which channel frames do not have");
  }
  if (levels.volumes.size() != static_cast<std::size_t>(set.size())) {
    throw InputError("channel reference: levels for " + std::to_string(levels.volumes.size()) +
                     " channels, the set has " + std::to_string(set.size()));
  }
  for (std::size_t l = 0; l + 1 < n.size(); ++l) {
    if (n[l] == 0) continue;
    for (const auto& perLevel : levels.volumes) {
      if (l >= perLevel.size() || !perLevel[l] || l >= levels.scales.size()) {
        throw InputError("channel reference: " + std::to_string(n[l]) + " cells show level " +
                         std::to_string(l) + ", which is not read");
      }
    }
  }
}

Image render(const ChannelSet& set, const ChannelLevels* levels, const TransferFunction& tf,
             const Camera& camera, const RenderSettings& settings, int width, int height,
             int threads);

}  // namespace

ChannelSample combineChannels(const ChannelSet& channels, const double* opacities) {
  ChannelSample s;
  double transmittance = 1.0;
  for (int i = 0; i < channels.size(); ++i) {
    if (!channels[i].visible) continue;
    s.premultiplied += opacities[i] * channels[i].color;
    transmittance *= 1.0 - opacities[i];
  }
  s.alpha = 1.0 - transmittance;
  // A premultiplied colour never exceeds its opacity: where channels of the
  // same hue overlap, the sum is clamped to it.
  s.premultiplied = glm::min(s.premultiplied, glm::dvec3(s.alpha));
  return s;
}

Image renderChannelsReference(const ChannelSet& set, const TransferFunction& tf,
                              const Camera& camera, const RenderSettings& settings, int width,
                              int height, int threads) {
  return render(set, nullptr, tf, camera, settings, width, height, threads);
}

Image renderChannelsReference(const ChannelSet& set, const ChannelLevels& levels,
                              const TransferFunction& tf, const Camera& camera,
                              const RenderSettings& settings, int width, int height, int threads) {
  checkLevels(set, levels);
  return render(set, &levels, tf, camera, settings, width, height, threads);
}

namespace {

Image render(const ChannelSet& set, const ChannelLevels* levels, const TransferFunction& tf,
             const Camera& camera, const RenderSettings& settings, int width, int height,
             int threads) {
  if (width <= 0 || height <= 0) throw InputError("reference: image size must be positive");
  const Volume& box = set.geometry();
  const glm::dvec3 extent = box.extent();
  const double ds = sampleDistance(settings, box.spacing());
  const glm::dvec4 bg = settings.background;
  const bool max = set.mode == ChannelMode::Max;
  Image image(width, height);
  std::atomic<int> nextRow{0};
  auto worker = [&] {
    for (int py = nextRow++; py < height; py = nextRow++) {
      for (int px = 0; px < width; ++px) {
        const Ray ray = camera.pixelRay(px, py, width, height);
        const glm::dvec3 to = ray.origin / extent + 0.5;
        const glm::dvec3 td = ray.direction / extent;
        const auto [t0, t1] = unitBoxSpan(to, td);
        glm::dvec4 acc(0.0);
        ChannelValues peak{};
        bool any = false;
        const double j = settings.jitter
                             ? jitterOffset(static_cast<unsigned>(px), static_cast<unsigned>(py))
                             : 0.5;
        for (double k = 0.0; t0 < t1 && k < settings.maxSteps; k += 1.0) {
          const double t = t0 + (k + j) * ds;
          if (t >= t1) break;
          const ChannelValues n = normalisedAt(set, levels, to + t * td);
          any = true;
          if (max) {
            for (std::size_t i = 0; i < peak.size(); ++i) peak[i] = std::max(peak[i], n[i]);
            continue;
          }
          ChannelValues a{};
          for (int i = 0; i < set.size(); ++i) {
            const auto u = static_cast<std::size_t>(i);
            a[u] = set[i].visible ? tf.correctedOpacity(n[u], ds, settings.opacityScale) : 0.0;
          }
          const ChannelSample s = combineChannels(set, a.data());
          acc += (1.0 - acc.a) * glm::dvec4(s.premultiplied, s.alpha);
          if (acc.a >= settings.ertThreshold) break;
        }
        if (max && any) {
          // Per channel maximum intensity projection, colours summed, opaque.
          glm::dvec3 rgb(0.0);
          for (int i = 0; i < set.size(); ++i) {
            rgb += peak[static_cast<std::size_t>(i)] * set[i].color;
          }
          acc = glm::dvec4(glm::min(rgb, glm::dvec3(1.0)), 1.0);
        }
        const glm::dvec4 out(glm::dvec3(acc) + (1.0 - acc.a) * glm::dvec3(bg),
                             acc.a + (1.0 - acc.a) * bg.a);
        std::uint8_t* pix = image.pixel(px, py);
        for (int c = 0; c < 4; ++c) pix[c] = toByte(out[c]);
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

}  // namespace

}  // namespace tessera
