#pragma once
// Parameters every renderer (GPU techniques and the CPU reference) honours
// with identical meaning, so that their images can be compared pixel by pixel.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace tessera {

// Composite: front-to-back emission-absorption. The projections show one
// value per ray, as the TF colour of that normalised value, opaque where the
// ray keeps a sample: Mip the largest sample (maximum intensity projection),
// MinIp the smallest, Average the mean of the ray's samples (average
// intensity projection, an X-ray-like view).
enum class RenderMode { Composite, Mip, MinIp, Average };

// The modes' names in the enum's order: the one list that option help,
// parsers and saved settings take them from, so that a new mode is named
// once.
inline constexpr std::array<std::string_view, 4> renderModeNames() {
  return {"composite", "mip", "minip", "average"};
}
static_assert(static_cast<std::size_t>(RenderMode::Average) + 1 == renderModeNames().size(),
              "every RenderMode needs its name in renderModeNames()");

inline constexpr std::string_view renderModeToName(RenderMode mode) {
  return renderModeNames()[static_cast<std::size_t>(mode)];
}
// The mode of that name; none for a word that names no mode.
inline constexpr std::optional<RenderMode> renderModeFromName(std::string_view name) {
  for (std::size_t i = 0; i < renderModeNames().size(); ++i) {
    if (renderModeNames()[i] == name) return static_cast<RenderMode>(i);
  }
  return std::nullopt;
}
// "composite, mip, minip or average": the list as help and errors write it.
std::string renderModeChoices();

inline bool isProjection(RenderMode mode) {
  return mode != RenderMode::Composite;
}

// Blinn-Phong shading of composited samples from the gradient of the
// reconstructed field (the layout seam's sampleVolumeGradient, the
// reference's Reconstruction::gradient): central differences one voxel apart
// on the same continuous field, so every path lights the same normals.
// Two-sided (|N.L|): a volume has no inside or outside. MIP is not shaded.
struct Shading {
  bool enabled = false;
  double ambient = 0.3;
  double diffuse = 0.6;
  double specular = 0.3;
  double shininess = 24.0;
  // Headlight: light from the viewer, along the view direction. Otherwise a
  // fixed light from lightDirection (towards the light, patient frame RAS+),
  // which turns with the volume.
  bool headlight = true;
  glm::dvec3 lightDirection{0.0, 1.0, 1.0};
  // Gradient-magnitude opacity modulation (Levoy 1988's idea in its simplest
  // form): a sample's opacity is scaled by clamp((|g| - low) / (high - low),
  // 0, 1), g the same gradient the light uses (normalised value per voxel of
  // the smallest spacing), so homogeneous regions fade and boundaries stay.
  // It works with or without the light (`enabled`).
  bool gradientOpacity = false;
  double gradientLow = 0.01;
  double gradientHigh = 0.06;
};

// A clip plane: keeps the points x (world units from the volume box's
// centre, patient-frame axes RAS+) with dot(normal, x) <= distance, i.e. cuts
// away what lies beyond `distance` along `normal`.
struct ClipPlane {
  glm::dvec3 normal{0.0, 0.0, 1.0};
  double distance = 0.0;
};

constexpr int kMaxClipPlanes = 6;

// Clip planes and an axis-aligned crop box. Clipping drops samples, it never
// moves them: samples stay at t0 + (k + j) ds from the volume box's entry, so
// moving a plane only adds or removes the samples it passes (no shimmering).
struct Clipping {
  std::vector<ClipPlane> planes;  // at most kMaxClipPlanes
  // The crop box in normalised volume coordinates ([0,1] along each index
  // axis, voxel centres at (i + 0.5) / dims); samples outside are dropped.
  glm::dvec3 cropMin{0.0};
  glm::dvec3 cropMax{1.0};
  bool cropped() const { return cropMin != glm::dvec3(0.0) || cropMax != glm::dvec3(1.0); }
  bool active() const { return !planes.empty() || cropped(); }
};

// Fewer samples for the same image (docs/sampling.md). Both apply to the
// composite mode of the ray caster and its CPU reference only (the projections
// need every sample, labels are not interpolated, the slicers draw planes).
//
// Pre-integrated classification (Engel et al. 2001): each segment between two
// consecutive samples is classified by its front and back values, the TF
// integrated over the values in between as if the field ran linearly from one
// to the other (reference/PreIntegration.h), instead of by one value per
// sample (post-classification); large steps then miss no thin TF feature.
//
// Adaptive sampling: inside blocks of the empty-space grid where the TF varies
// little over the block's value range, samples are taken every m-th step of
// the base lattice t0 + (k + j) ds (m = 2, 4, ... up to maxMultiplier; m k
// still on the lattice, so samples never move), with opacity corrected for
// the longer segment: a' = 1 - (1 - a)^m (reference/AdaptiveSteps.h).
struct Sampling {
  bool preintegrate = false;
  // With preintegrate: only frames whose samples take the gradient (shading
  // or gradient-opacity modulation) pre-integrate; the others are
  // post-classified (--preintegrate lit).
  bool preintegrateLitOnly = false;
  bool adaptive = false;
  // A block gets the largest m with m * ds * V <= tolerance, where V is the
  // TF's variation over the block's value range (extinction per world unit
  // plus extinction-weighted colour, max minus min): the bound on what a
  // segment of length m ds can get wrong there.
  double tolerance = 0.1;
  // The tolerance of lit frames (shading or gradient opacity: the light
  // shows what a long stretch smooths over); < 0: `tolerance`.
  double litTolerance = -1.0;
  int maxMultiplier = 16;  // a power of two, 1..64
  // Behind accumulated opacity A a stretch's error reaches the pixel (1 - A)
  // times weaker, so steps grow by 2^floor(-log2(1 - A)) (Danskin & Hanrahan
  // 1992's opacity-based acceleration): the transmittance-weighted error of a
  // step never exceeds what the block's multiplier allows at full
  // transmittance. Still on the lattice, still capped by maxMultiplier.
  bool opacityGrowth = true;
};

// The sampling `tessera render`, `tessera view` and the web page start with
// (docs/sampling.md, "Defaults"): the fastest settings measured to keep
// >= 40 dB against a 0.25-voxel reference on every volume, TF and shading
// tried: post-classified adaptive steps, tolerance 0.5 unlit and 0.25 lit
// (faster than pre-integration at 0.5, and above the bar where that fell to
// 36 dB). Sampling{} itself stays plain post-classified sampling, the
// baseline the tests and benches compare against.
constexpr Sampling defaultSampling() {
  Sampling s;
  s.preintegrate = false;
  s.adaptive = true;
  s.tolerance = 0.5;
  s.litTolerance = 0.25;
  s.maxMultiplier = 16;
  s.opacityGrowth = true;
  return s;
}
// The default base step (voxels of the smallest spacing) that goes with it.
constexpr double kDefaultStepVoxels = 0.5;

struct RenderSettings {
  RenderMode mode = RenderMode::Composite;
  Shading shading;
  Clipping clipping;
  // Nearest-neighbour reconstruction: a sample takes the value of the voxel
  // whose cell holds it (label volumes: no interpolation across labels).
  bool nearest = false;
  Sampling sampling;
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

// RenderSettings with the default sampling and step above: what the front
// ends (CLI and viewers) render with unless the user says otherwise.
inline RenderSettings defaultRenderSettings() {
  RenderSettings s;
  s.sampling = defaultSampling();
  s.stepVoxels = kDefaultStepVoxels;
  return s;
}

// The sample distance in world units, ds = stepVoxels * min(spacing): the
// one place every renderer (GPU techniques and the reference) computes it.
// InputError unless the step is a positive finite number (the engine's
// invariant; the user's range is session::kStepRange, checked once by
// session::Settings).
double sampleDistance(const RenderSettings& settings, glm::dvec3 spacing);

// Whether the samples of a render with these settings take the gradient
// (shading or gradient-opacity modulation; composite mode).
inline bool litSamples(const RenderSettings& s) {
  return (s.shading.enabled || s.shading.gradientOpacity) && s.mode == RenderMode::Composite;
}

// Whether a render with these settings pre-integrates / samples adaptively
// (both: composite mode, interpolated values).
inline bool usesPreintegration(const RenderSettings& s) {
  return s.sampling.preintegrate && (!s.sampling.preintegrateLitOnly || litSamples(s)) &&
         s.mode == RenderMode::Composite && !s.nearest;
}
// The adaptive tolerance a render with these settings uses.
inline double adaptiveTolerance(const RenderSettings& s) {
  return litSamples(s) && s.sampling.litTolerance >= 0.0 ? s.sampling.litTolerance
                                                         : s.sampling.tolerance;
}
inline bool usesAdaptiveSampling(const RenderSettings& s) {
  return s.sampling.adaptive && s.mode == RenderMode::Composite && !s.nearest;
}

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

// The light of one frame in the volume's model frame: l towards the light, h
// the Blinn half vector between l and the direction to the viewer.
struct ShadingLight {
  glm::dvec3 l{0.0, 0.0, 1.0};
  glm::dvec3 h{0.0, 0.0, 1.0};
};

// `back` is the camera's back vector (towards the viewer, model frame),
// `modelFromWorld` Camera::modelFromWorld.
inline ShadingLight shadingLight(const Shading& shading, glm::dvec3 back,
                                 const glm::dmat3& modelFromWorld) {
  ShadingLight light;
  const glm::dvec3 v = glm::normalize(back);
  light.l = shading.headlight ? v : glm::normalize(modelFromWorld * shading.lightDirection);
  const glm::dvec3 half = light.l + v;
  light.h = glm::length(half) > 1e-9 ? glm::normalize(half) : light.l;
  return light;
}

// Below this gradient magnitude (normalised value per voxel of the smallest
// spacing) a sample fades to ambient light: the normal is g / sqrt(|g|^2 +
// eps^2), continuous, so noise in flat regions is not lit as surfaces and the
// GPU's float and the reference's double agree near zero.
constexpr double kShadingGradientEpsilon = 0.01;

// The shaded colour of straight colour `rgb` at a sample whose field gradient
// is `g` (normalised value per smallest-voxel length, model frame). The GLSL
// twin is render/shading.glsl.
inline glm::dvec3 shadeBlinnPhong(glm::dvec3 rgb, glm::dvec3 g, const Shading& shading,
                                  const ShadingLight& light) {
  const glm::dvec3 n =
      g / std::sqrt(glm::dot(g, g) + kShadingGradientEpsilon * kShadingGradientEpsilon);
  const double diffuse = std::abs(glm::dot(n, light.l));
  const double specular = std::pow(std::abs(glm::dot(n, light.h)), shading.shininess);
  const glm::dvec3 lit =
      rgb * (shading.ambient + shading.diffuse * diffuse) + glm::dvec3(shading.specular * specular);
  return glm::min(lit, glm::dvec3(1.0));
}

// The opacity factor of gradient-magnitude modulation for gradient `g`
// (Shading::gradientOpacity). The GLSL twin is render/shading.glsl's
// gradientOpacity().
inline double gradientOpacityFactor(glm::dvec3 g, const Shading& shading) {
  return std::clamp(
      (glm::length(g) - shading.gradientLow) / (shading.gradientHigh - shading.gradientLow), 0.0,
      1.0);
}

// What a sample's light does with its colour: Blinn-Phong where the light is
// on, the colour unchanged where only the gradient's opacity modulation
// needs the gradient (Shading::gradientOpacity without `enabled`).
inline glm::dvec3 lightSample(glm::dvec3 rgb, glm::dvec3 g, const Shading& shading,
                              const ShadingLight& light) {
  return shading.enabled ? shadeBlinnPhong(rgb, g, shading, light) : rgb;
}

// The clip planes as half-spaces of texture space (p in [0,1]^3, the volume
// box): p is kept where dot(h.xyz, p) <= h.w for every h. `modelFromWorld`:
// Camera::modelFromWorld (a rotation), `extent`: the box's world size.
inline std::vector<glm::dvec4> clipHalfSpaces(const Clipping& clipping,
                                              const glm::dmat3& modelFromWorld, glm::dvec3 extent) {
  std::vector<glm::dvec4> out;
  for (const ClipPlane& c : clipping.planes) {
    // x = (p - 0.5) * extent in the model frame.
    const glm::dvec3 a = (modelFromWorld * c.normal) * extent;
    out.emplace_back(a, c.distance + glm::dot(a, glm::dvec3(0.5)));
  }
  return out;
}

// Whether the sample at texture-space p survives clipping (the GLSL twin is
// render/clipping.glsl).
inline bool clipKeeps(const Clipping& clipping, const std::vector<glm::dvec4>& halfSpaces,
                      glm::dvec3 p) {
  for (int a = 0; a < 3; ++a) {
    if (p[a] < clipping.cropMin[a] || p[a] > clipping.cropMax[a]) return false;
  }
  for (const glm::dvec4& h : halfSpaces) {
    if (glm::dot(glm::dvec3(h), p) > h.w) return false;
  }
  return true;
}

}  // namespace tessera
