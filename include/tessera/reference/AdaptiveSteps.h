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
  // Per block, the chessboard distance in blocks to the nearest visible one
  // (0: visible; at most 255): an empty block at distance d lies in a cube of
  // empty blocks d - 1 blocks around it, which a ray leaves in one step
  // (distance-based empty-space skipping). Filled by measureEmptySpace().
  std::vector<std::uint8_t> emptyDistance;

  // Fills emptyDistance from codes (two raster passes, exact for the
  // chessboard metric).
  void measureEmptySpace();
  std::uint8_t distance(glm::ivec3 cell) const {
    if (emptyDistance.empty()) return code(cell) != 0 ? 0 : 1;
    return emptyDistance[(static_cast<std::size_t>(cell.z) * count.y + cell.y) * count.x + cell.x];
  }

  bool valid() const { return blockSize > 0 && !codes.empty(); }
  // The cell holding texture-space point p (clamped to the grid), as the
  // shader computes it: floor(p * dims / blockSize).
  glm::ivec3 cellAt(glm::dvec3 p) const;
  std::uint8_t code(glm::ivec3 cell) const {
    return codes[(static_cast<std::size_t>(cell.z) * count.y + cell.y) * count.x + cell.x];
  }
  // Ray parameter t where the ray to + t td leaves `cell`.
  double exitT(glm::ivec3 cell, glm::dvec3 to, glm::dvec3 td) const { return exit(cell, to, td).t; }
  // That t, and where the ray leaves the block it enters there (across the
  // face it leaves by; the first axis on a tie, as the shader).
  struct Exit {
    double t;
    double tNext;
  };
  // With `radius` > 0, t is where the ray leaves the cube of blocks within
  // that chessboard distance of `cell`.
  Exit exit(glm::ivec3 cell, glm::dvec3 to, glm::dvec3 td, int radius = 0) const;
  // The smallest code of the six face neighbours of `cell`, 0 when one is
  // empty or outside the grid: a bound on the code of whichever block a ray
  // enters next (the GPU reads it with the block, channel a).
  std::uint8_t aheadCode(glm::ivec3 cell) const;
  bool contains(glm::ivec3 cell) const {
    return cell.x >= 0 && cell.y >= 0 && cell.z >= 0 && cell.x < count.x && cell.y < count.y &&
           cell.z < count.z;
  }
};

// The code of a visible block without adaptive steps (s = 1: m = 1).
constexpr std::uint8_t kUnitStepCode = 64;

// The multiplier for a visible block's code behind accumulated opacity
// `alpha` (0 without opacity growth); `maxMultiplier` a power of two. The GLSL
// twin is raycast.frag.glsl's stepMultipliers().
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
// first passed by sample kExit (> k), the next sample is the next multiple
// of m after k while that stays inside the block: at most kExit
// (post-classification: the sample stands for the stretch up to the next
// one) or kExit - 1 (pre-integration: the segment ends before the face).
// Past that, the walk looks one block ahead: the block the ray enters across
// the face it leaves by (`ahead`, its multiplier mAhead and exit sample
// kExitAhead; mAhead = 0 when there is none or it is empty). A stretch or
// segment may cross the face with min(m, mAhead), up to kExitAhead
// (post-classification) or kExitAhead - 1 (pre-integration), so that it lies
// in the two blocks whose allowances it keeps, and never shorter than one
// base step. Without a block ahead it stops at kExit (post) or crosses the
// face in one base step from kExit - 1 (pre), since the blocks on either side
// may differ completely. Empty blocks (code 0) are left for kExit; a
// pre-integrated ray then composites the segment from the last sample before
// the block to its first sample inside it, and starts again with the segment
// (kExit - 1, kExit): every segment it leaves out lies in values the TF makes
// transparent.
struct StepsAhead {
  double m = 0.0;      // the next block's multiplier; 0: no block ahead, or an empty one
  double kExit = 0.0;  // its exit sample
};

inline double nextMultiple(double k, double m) {
  return (std::floor(k / m) + 1.0) * m;
}

inline double nextAdaptiveSample(double k, double m, double kExit, StepsAhead ahead,
                                 bool preintegrated) {
  const double last = preintegrated ? kExit - 1.0 : kExit;
  const double aligned = nextMultiple(k, m);
  if (aligned <= last) return aligned;
  if (ahead.m <= 0.0) return std::max(k + 1.0, last);
  const double end = preintegrated ? ahead.kExit - 1.0 : ahead.kExit;
  return std::max(k + 1.0, std::min(nextMultiple(k, std::min(m, ahead.m)), end));
}

// The first base sample at or past parameter tExit: max(ceil((tExit - t0)/ds - j), k + 1).
inline double exitSample(double tExit, double t0, double ds, double j, double k) {
  return std::max(std::ceil((tExit - t0) / ds - j), k + 1.0);
}

}  // namespace tessera
