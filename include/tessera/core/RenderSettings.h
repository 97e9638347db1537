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
  // Per-pixel offset of the first sample in [0,1) from an ordered-dither
  // pattern (jitterOffset, same on GPU and CPU); otherwise samples sit at
  // t0 + (k + 0.5) ds.
  bool jitter = false;
  // Composited behind the volume: out = C + (1 - A) * background.
  glm::dvec4 background{0.0, 0.0, 0.0, 1.0};
};

// Jitter offset of pixel (x, y) (y from the top row): an 8x8 ordered-dither
// (Bayer) pattern, (M(x mod 8, y mod 8) + 0.5) / 64, where the base-4 digit i
// of M is 2 * (x_i xor y_i) + y_i for bit i of x and y. Small integers only,
// so the GLSL twin (render/camera_ray.glsl) is exact even in GLSL ES 1.00,
// which has no integer bit operations.
inline double jitterOffset(unsigned x, unsigned y) {
  unsigned v = 0;
  for (unsigned i = 0; i < 3; ++i) {
    const unsigned xi = (x >> i) & 1u, yi = (y >> i) & 1u;
    v += (2u * (xi ^ yi) + yi) << (2u * (2u - i));
  }
  return (v + 0.5) / 64.0;
}

}  // namespace tessera
