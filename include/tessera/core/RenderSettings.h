#pragma once
// Parameters every renderer (GPU techniques and the CPU reference) honours
// with identical meaning, so that their images can be compared pixel by pixel.
#include <glm/vec4.hpp>

namespace tessera {

// Composite: front-to-back emission-absorption. Mip: maximum intensity
// projection; the pixel is the TF colour of the largest normalised sample
// along the ray, opaque where the ray meets the volume.
enum class RenderMode { Composite, Mip };

struct RenderSettings {
  RenderMode mode = RenderMode::Composite;
  // Sample distance in voxels of the smallest spacing: ds = stepVoxels * min(spacing).
  double stepVoxels = 0.5;
  // Upper bound on samples per ray (Schultz 2016, 7.2.3).
  int maxSteps = 4096;
  // Multiplies every TF opacity before distance correction (Schultz's alpha).
  double opacityScale = 1.0;
  // Early ray termination: stop once accumulated alpha >= this. >= 1 disables it.
  double ertThreshold = 0.99;
  // Per-pixel offset of the first sample in [0,1) from an integer hash of the
  // pixel (same hash on GPU and CPU); otherwise samples sit at t0 + (k + 0.5) ds.
  bool jitter = false;
  // Composited behind the volume: out = C + (1 - A) * background.
  glm::dvec4 background{0.0, 0.0, 0.0, 1.0};
};

// The pixel hash used for jitter: a PCG-style integer hash of (x, y),
// returned as a fraction in [0,1). GLSL twin in render/common.glsl.
inline double jitterOffset(unsigned x, unsigned y) {
  unsigned v = x * 1973u + y * 9277u + 26699u;
  v = v * 747796405u + 2891336453u;
  unsigned w = ((v >> ((v >> 28u) + 4u)) ^ v) * 277803737u;
  w = (w >> 22u) ^ w;
  return static_cast<double>(w >> 8) / 16777216.0;
}

}  // namespace tessera
