#include "tessera/reference/ReferenceRaycaster.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <optional>
#include <thread>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "tessera/core/Error.h"
#include "tessera/reference/PreIntegration.h"

namespace tessera {

namespace {

std::uint8_t toByte(double v) {
  return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
}

}  // namespace

double sampleTrilinear(const Volume& volume, glm::dvec3 p) {
  const glm::ivec3 d = volume.dims();
  const glm::dvec3 u = p * glm::dvec3(d) - 0.5;
  const glm::dvec3 f = glm::floor(u);
  const glm::dvec3 w = u - f;
  const glm::ivec3 i0 = glm::clamp(glm::ivec3(f), glm::ivec3(0), d - 1);
  const glm::ivec3 i1 = glm::clamp(glm::ivec3(f) + 1, glm::ivec3(0), d - 1);
  double acc = 0.0;
  for (int c = 0; c < 8; ++c) {
    const int x = (c & 1) ? i1.x : i0.x, y = (c & 2) ? i1.y : i0.y, z = (c & 4) ? i1.z : i0.z;
    const double wt =
        ((c & 1) ? w.x : 1 - w.x) * ((c & 2) ? w.y : 1 - w.y) * ((c & 4) ? w.z : 1 - w.z);
    acc += wt * volume.finiteValueAtIndex(volume.index(x, y, z));
  }
  return acc;
}

std::pair<double, double> unitBoxSpan(glm::dvec3 to, glm::dvec3 td) {
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
  return {std::max(tNear, 0.0), tFar};
}

Image renderReference(const Volume& volume, const TransferFunction& tf, const Camera& camera,
                      const RenderSettings& settings, int width, int height, int threads,
                      ReferenceStats* stats, const ReferenceStops* stops, const StepGrid* steps,
                      const FusionTwin* fusion) {
  if (settings.nearest) {
    return renderReference(volume, NearestReconstruction(volume), tf, camera, settings, width,
                           height, threads, stats, stops, steps, fusion);
  }
  return renderReference(volume, TrilinearReconstruction(volume), tf, camera, settings, width,
                         height, threads, stats, stops, steps, fusion);
}

Image renderReference(const Volume& volume, const Reconstruction& field, const TransferFunction& tf,
                      const Camera& camera, const RenderSettings& settings, int width, int height,
                      int threads, ReferenceStats* stats, const ReferenceStops* stops,
                      const StepGrid* steps, const FusionTwin* fusion) {
  if (width <= 0 || height <= 0) throw InputError("reference: image size must be positive");
  const glm::dvec3 extent = volume.extent();
  const glm::dvec3 spacing = volume.spacing();
  const double ds = sampleDistance(settings, spacing);
  const ValueRange win = volume.window();
  const double ww = win.max - win.min;
  const glm::dvec4 bg = settings.background;
  // Shading (core/RenderSettings.h): the field's gradient per texture unit ->
  // normalised value per model length, times the smallest voxel.
  // With gradient-opacity modulation the gradient is needed without the
  // light too (lightSample leaves the colour then).
  const bool shade = (settings.shading.enabled || settings.shading.gradientOpacity) &&
                     settings.mode == RenderMode::Composite;
  const bool modulate = shade && settings.shading.gradientOpacity;
  const ShadingLight light =
      shadingLight(settings.shading, camera.basis()[2], camera.modelFromWorld);
  const std::vector<glm::dvec4> clipPlanes =
      clipHalfSpaces(settings.clipping, camera.modelFromWorld, extent);
  const glm::dvec3 gradientScale = std::min({spacing.x, spacing.y, spacing.z}) / (ww * extent);
  // Pre-integration and the block walk (docs/sampling.md): segments between
  // consecutive samples classified by their two values; with a grid, the
  // GPU's walk over it (empty blocks left at once, adaptive steps).
  const bool pre = usesPreintegration(settings);
  const std::optional<PreIntegral> integral =
      pre ? std::optional<PreIntegral>(std::in_place, tf, settings.opacityScale) : std::nullopt;
  const bool walk = steps != nullptr && steps->valid() && settings.mode == RenderMode::Composite &&
                    !settings.nearest;
  if (walk && steps->dims != volume.dims()) {
    throw Error("reference: the step grid was made for another volume");
  }
  const bool clipped = settings.clipping.active();
  const bool adaptive = walk && settings.sampling.adaptive;
  const bool grow = adaptive && settings.sampling.opacityGrowth;

  Image image(width, height);
  std::atomic<int> nextRow{0};
  std::atomic<std::uint64_t> totalSamples{0}, totalHits{0}, totalSteps{0};
  auto worker = [&] {
    std::uint64_t samples = 0, hits = 0, visits = 0;
    for (int py = nextRow++; py < height; py = nextRow++) {
      for (int px = 0; px < width; ++px) {
        // An opaque stop (overlay line) ends the ray and replaces the background.
        const std::uint8_t* stopColor = stops ? stops->color.pixel(px, py) : nullptr;
        const bool stopped = stopColor != nullptr && stopColor[3] > 0;
        const double tStop =
            stopped
                ? static_cast<double>(stops->distance[static_cast<std::size_t>(py) * width + px])
                : std::numeric_limits<double>::infinity();
        const Ray ray = camera.pixelRay(px, py, width, height);
        // Texture space, as on the GPU: t stays in world units.
        const glm::dvec3 to = ray.origin / extent + 0.5;
        const glm::dvec3 td = ray.direction / extent;
        // Not a structured binding: lambdas below use t0 (clang 14, the
        // web build's, cannot capture those).
        const std::pair<double, double> span = unitBoxSpan(to, td);
        const double t0 = span.first;
        const double tFar = span.second;
        const double tEnd = std::min(tFar, tStop);
        glm::dvec4 acc(0.0);
        double maxValue = -1.0;
        double minValue = 2.0, sumValue = 0.0;
        std::uint64_t kept = 0;
        if (t0 < tEnd) {
          ++hits;
          // Pre-integrated samples sit half a step earlier, one more of them
          // (raycast.frag.glsl): segment k-1..k covers what post-classified
          // sample k - 1 stands for.
          const double j =
              (settings.jitter ? jitterOffset(static_cast<unsigned>(px), static_cast<unsigned>(py))
                               : 0.5) -
              (pre ? 0.5 : 0.0);
          const double tLast = pre ? std::min(tFar + 0.5 * ds, tStop) : tEnd;
          const auto normalised = [&](glm::dvec3 p) {
            return std::clamp((field.value(p) - win.min) / ww, 0.0, 1.0);
          };
          const auto keeps = [&](glm::dvec3 p) {
            return clipKeeps(settings.clipping, clipPlanes, p);
          };
          // The twin of the GPU's segment: straight colour lit at the
          // segment's middle, opacity for its length.
          const auto composite = [&](double nf, double nb, double kf, double kb) {
            glm::dvec4 s = integral->segment(nf, nb, (kb - kf) * ds);
            glm::dvec3 c(s);
            if (shade && s.a > 0.0) {
              // As the GPU: the segment's opacity for its length, then lit
              // and modulated at its middle.
              const glm::dvec3 mid = to + (t0 + (0.5 * (kf + kb) + j) * ds) * td;
              const glm::dvec3 g = field.gradient(mid) * gradientScale;
              c = lightSample(c, g, settings.shading, light);
              if (modulate) s.a *= gradientOpacityFactor(g, settings.shading);
            }
            acc += (1.0 - acc.a) * glm::dvec4(c * s.a, s.a);
          };
          double k = 0.0;
          if (clipped) {
            // As the GPU: start at the box-aligned sample at or before the
            // crop box's entry (samples before it are dropped either way).
            double cropEnter = -std::numeric_limits<double>::infinity();
            for (int a = 0; a < 3; ++a) {
              const double inv = (td[a] >= 0.0 ? 1.0 : -1.0) / std::max(std::abs(td[a]), 1e-20);
              const double ta = (settings.clipping.cropMin[a] - to[a]) * inv;
              const double tb = (settings.clipping.cropMax[a] - to[a]) * inv;
              cropEnter = std::max(cropEnter, std::min(ta, tb));
            }
            k = std::max(0.0, std::floor((cropEnter - t0) / ds - j));
          }
          double frontN = 0.0, frontK = -1.0;  // pre-integration: the segment's front sample
          bool lazyFront = false;              // after an empty block: front at k - 1
          while (k < settings.maxSteps) {
            const double t = t0 + (k + j) * ds;
            if (t >= tLast) break;
            const glm::dvec3 p = to + t * td;
            double kNext = k + 1.0;
            ++visits;
            if (walk) {
              const glm::ivec3 cell = steps->cellAt(p);
              const std::uint8_t code = steps->code(cell);
              const double m =
                  code == 0 || !adaptive
                      ? 1.0
                      : stepMultiplier(code, grow ? acc.a : 0.0, settings.sampling.maxMultiplier);
              if (code == 0 || m > 1.0) {
                // An empty block is left with the cube of empty blocks
                // around it.
                const int radius = code == 0 ? std::max(steps->distance(cell) - 1, 0) : 0;
                const StepGrid::Exit exit = steps->exit(cell, to, td, radius);
                const double kExit = exitSample(exit.t, t0, ds, j, k);
                if (code == 0) {
                  if (pre && frontK >= 0.0 && keeps(p)) {
                    ++samples;
                    composite(frontN, normalised(p), frontK, k);
                  }
                  frontK = -1.0;
                  lazyFront = pre;
                  k = kExit;
                  if (acc.a >= settings.ertThreshold) break;
                  continue;
                }
                // The block ahead, bounded as the GPU reads it (AdaptiveSteps.h).
                StepsAhead ahead;
                if (const std::uint8_t a = steps->aheadCode(cell); a != 0) {
                  ahead.m = stepMultiplier(a, grow ? acc.a : 0.0, settings.sampling.maxMultiplier);
                  ahead.kExit = exitSample(exit.tNext, t0, ds, j, k);
                }
                kNext = nextAdaptiveSample(k, m, kExit, ahead, pre);
              }
            }
            ++samples;
            if (clipped && !keeps(p)) {  // dropped, not moved
              frontK = -1.0;
              lazyFront = false;
              k = kNext;
              continue;
            }
            const double n = normalised(p);
            if (isProjection(settings.mode)) {
              maxValue = std::max(maxValue, n);
              minValue = std::min(minValue, n);
              sumValue += n;
              ++kept;
              k = kNext;
              continue;
            }
            if (pre) {
              if (frontK < 0.0 && lazyFront) {
                const glm::dvec3 p1 = to + (t - ds) * td;
                if (!clipped || keeps(p1)) {
                  ++samples;
                  frontN = normalised(p1);
                  frontK = k - 1.0;
                }
              }
              if (frontK >= 0.0) composite(frontN, n, frontK, k);
              frontN = n;
              frontK = k;
              lazyFront = false;
            } else {
              glm::dvec3 c = tf.color(n);
              // A sample stands for the stretch to the next one.
              double a = tf.correctedOpacity(n, ds * (kNext - k), settings.opacityScale);
              if (fusion) {  // the second volume over this sample (FusedVolume.h)
                const glm::dvec4 f = fusion->fuse(c, a, p, ds * (kNext - k));
                c = glm::dvec3(f);
                a = f.a;
              }
              if (shade && a > 0.0) {
                const glm::dvec3 g = field.gradient(p) * gradientScale;
                c = lightSample(c, g, settings.shading, light);
                if (modulate) {
                  // As the GPU: the base step's opacity modulated, then
                  // corrected for the stretch the sample stands for.
                  const double a1 = tf.correctedOpacity(n, ds, settings.opacityScale) *
                                    gradientOpacityFactor(g, settings.shading);
                  a = 1.0 - std::pow(1.0 - a1, kNext - k);
                }
              }
              acc += (1.0 - acc.a) * glm::dvec4(c * a, a);
            }
            if (acc.a >= settings.ertThreshold) break;
            k = kNext;
          }
        }
        if (isProjection(settings.mode) && kept > 0) {
          // The projections show the TF colour of their value, opaque.
          const double shown = settings.mode == RenderMode::Mip     ? maxValue
                               : settings.mode == RenderMode::MinIp ? minValue
                                                                    : sumValue / kept;
          acc = glm::dvec4(tf.color(shown), 1.0);
        }
        const glm::dvec4 under =
            stopped ? glm::dvec4(glm::dvec3(stopColor[0], stopColor[1], stopColor[2]) / 255.0, 1.0)
                    : bg;
        const glm::dvec4 out(glm::dvec3(acc) + (1.0 - acc.a) * glm::dvec3(under),
                             acc.a + (1.0 - acc.a) * under.a);
        std::uint8_t* pix = image.pixel(px, py);
        for (int ch = 0; ch < 4; ++ch) pix[ch] = toByte(out[ch]);
      }
    }
    totalSamples += samples;
    totalHits += hits;
    totalSteps += visits;
  };
  const int n =
      threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::vector<std::thread> pool;
  for (int i = 0; i < n; ++i) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  if (stats) {
    stats->samples = totalSamples;
    stats->raysHittingVolume = totalHits;
    stats->steps = totalSteps;
  }
  return image;
}

}  // namespace tessera
