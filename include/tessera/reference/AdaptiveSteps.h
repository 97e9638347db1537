#pragma once
// The block grid the ray caster walks with empty-space skipping and adaptive
// sampling, and the rule by which it walks it: shared by the GPU ray caster
// (render/Raycaster.cpp, which uploads the codes; render/raycast.frag.glsl)
// and the CPU reference (ReferenceRaycaster.cpp), so that both take the same
// samples (docs/sampling.md).
//
// Per block of B^3 voxels (the layout's ValueBlocks: the raw value range every
// sample inside the block can take), a code: 0 when the TF gives no value in
// that range any opacity (skipped), otherwise the block's step allowance
// s = tolerance / (ds * V) in eighths of an octave, code = 64 + floor(8 log2 s)
// (1..255), where V is the TF's variation over the block's range: (max - min
// of the extinction tau) + the largest over r, g, b of (max - min of
// tau * colour), per world unit. A stretch of length L inside such a block can
// differ from any finer sampling of it by at most about L * V in optical depth
// and emitted colour, whatever the field does there, and behind accumulated
// opacity A that difference reaches the pixel (1 - A) times weaker. So the ray
// samples every m-th point of its base lattice t0 + (k + j) ds there, with
//   m = 2^floor(log2(s / (1 - A))), clamped to 1..Sampling::maxMultiplier
// (without Sampling::opacityGrowth, A = 0): (1 - A) m ds V <= tolerance.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/core/RenderSettings.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/core/Volume.h"

namespace tessera {

struct StepGrid {
  glm::ivec3 dims{0};  // the volume's voxels
  int blockSize = 0;
  glm::ivec3 count{0};
  std::vector<std::uint8_t> codes;  // x fastest

  bool valid() const { return blockSize > 0 && !codes.empty(); }
  // The cell holding texture-space point p (clamped to the grid), as the
  // shader computes it: floor(p * dims / blockSize).
  glm::ivec3 cellAt(glm::dvec3 p) const;
  std::uint8_t code(glm::ivec3 cell) const {
    return codes[(static_cast<std::size_t>(cell.z) * count.y + cell.y) * count.x + cell.x];
  }
  // Ray parameter t where the ray to + t td leaves `cell`.
  double exitT(glm::ivec3 cell, glm::dvec3 to, glm::dvec3 td) const;
};

// The code of a visible block without adaptive steps (s = 1: m = 1).
constexpr std::uint8_t kUnitStepCode = 64;

// The multiplier for a visible block's code behind accumulated opacity
// `alpha` (0 without opacity growth); `maxMultiplier` a power of two. The GLSL
// twin is raycast.frag.glsl's stepMultiplier().
inline double stepMultiplier(std::uint8_t code, double alpha, int maxMultiplier) {
  const double e = std::floor((code - 64.0) / 8.0 - std::log2(std::max(1.0 - alpha, 1e-6)));
  return std::exp2(std::clamp(e, 0.0, std::log2(static_cast<double>(maxMultiplier))));
}

// The codes for blocks whose raw value ranges are mins[b]..maxs[b], seen
// through `window`, for a TF table of `tableEntries` entries per axis (the
// range is widened to the table's cells that its linear lookup mixes; 4096
// for the post-classification LUT, the pre-integration table's N otherwise).
// Without `adaptive` every visible block gets kUnitStepCode.
std::vector<std::uint8_t> classifyStepBlocks(const std::vector<float>& mins,
                                             const std::vector<float>& maxs, ValueRange window,
                                             const TransferFunction& tf, double opacityScale,
                                             double sampleDistance, int tableEntries,
                                             const Sampling& sampling, bool adaptive);

// The walk. At base sample k in a block with multiplier m whose exit is
// first passed by sample kExit (> k), the next sample is
//   post-classification: min(next multiple of m after k, kExit)
//   pre-integration:     k + 1 when k >= kExit - 1, else
//                        min(next multiple of m after k, kExit - 1)
// so pre-integrated segments that cross a block face are one base step long
// (the blocks on either side may differ completely). Empty blocks (code 0)
// are left for kExit; a pre-integrated ray then composites the segment from
// the last sample before the block to its first sample inside it, and starts
// again with the segment (kExit - 1, kExit): every segment it leaves out lies
// in values the TF makes transparent.
inline double nextAdaptiveSample(double k, double m, double kExit, bool preintegrated) {
  const double aligned = (std::floor(k / m) + 1.0) * m;
  if (!preintegrated) return std::min(aligned, kExit);
  return k >= kExit - 1.0 ? k + 1.0 : std::min(aligned, kExit - 1.0);
}

// The first base sample at or past parameter tExit: max(ceil((tExit - t0)/ds - j), k + 1).
inline double exitSample(double tExit, double t0, double ds, double j, double k) {
  return std::max(std::ceil((tExit - t0) / ds - j), k + 1.0);
}

}  // namespace tessera
