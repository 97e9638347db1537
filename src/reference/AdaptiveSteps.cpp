#include "tessera/reference/AdaptiveSteps.h"

#include <limits>
#include <string>
#include <unordered_map>

#include <glm/common.hpp>

#include "tessera/core/Error.h"

namespace tessera {

namespace {

// Range minimum and maximum queries in O(1) over a fixed array (sparse table).
class RangeExtremes {
 public:
  explicit RangeExtremes(const std::vector<double>& v) {
    const std::size_t n = v.size();
    lo_.push_back(v);
    hi_.push_back(v);
    for (std::size_t w = 1; 2 * w <= n; w *= 2) {
      const std::vector<double>& plo = lo_.back();
      const std::vector<double>& phi = hi_.back();
      std::vector<double> nlo(n - 2 * w + 1), nhi(n - 2 * w + 1);
      for (std::size_t i = 0; i + 2 * w <= n; ++i) {
        nlo[i] = std::min(plo[i], plo[i + w]);
        nhi[i] = std::max(phi[i], phi[i + w]);
      }
      lo_.push_back(std::move(nlo));
      hi_.push_back(std::move(nhi));
    }
  }
  // max - min over v[a..b], a <= b.
  double spread(std::size_t a, std::size_t b) const {
    std::size_t level = 0;
    while ((std::size_t{2} << level) <= b - a + 1) ++level;
    const std::size_t w = std::size_t{1} << level;
    const double mx = std::max(hi_[level][a], hi_[level][b + 1 - w]);
    const double mn = std::min(lo_[level][a], lo_[level][b + 1 - w]);
    return mx - mn;
  }

 private:
  std::vector<std::vector<double>> lo_, hi_;
};

// The largest TF opacity over [a, b]: a0 is piecewise linear, so at an end or
// at a control point inside.
double maxOpacity(const TransferFunction& tf, double a, double b) {
  double m = std::max(tf.opacity(a), tf.opacity(b));
  for (const OpacityPoint& p : tf.opacities) {
    if (p.x > a && p.x < b) m = std::max(m, p.alpha);
  }
  return m;
}

}  // namespace

glm::ivec3 StepGrid::cellAt(glm::dvec3 p) const {
  const glm::dvec3 c = glm::floor(p * glm::dvec3(dims) / static_cast<double>(blockSize));
  return glm::clamp(glm::ivec3(c), glm::ivec3(0), count - 1);
}

StepGrid::Exit StepGrid::exit(glm::ivec3 cell, glm::dvec3 to, glm::dvec3 td, int radius) const {
  const auto faceT = [&](glm::ivec3 c, int a) {
    const double face =
        (c[a] + (td[a] > 0.0 ? 1.0 + radius : -radius)) * blockSize / static_cast<double>(dims[a]);
    return (face - to[a]) / td[a];
  };
  Exit e{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  int axis = -1;
  for (int a = 0; a < 3; ++a) {
    if (td[a] == 0.0) continue;
    const double t = faceT(cell, a);
    if (t < e.t) {
      e.t = t;
      axis = a;
    }
  }
  if (axis < 0) return e;
  glm::ivec3 next = cell;
  next[axis] += td[axis] > 0.0 ? 1 : -1;
  for (int a = 0; a < 3; ++a) {
    if (td[a] != 0.0) e.tNext = std::min(e.tNext, faceT(next, a));
  }
  return e;
}

void StepGrid::measureEmptySpace() {
  constexpr int kFar = 1 << 20;
  std::vector<int> d(codes.size());
  for (std::size_t b = 0; b < codes.size(); ++b) d[b] = codes[b] != 0 ? 0 : kFar;
  const auto at = [&](int x, int y, int z) -> int& {
    return d[(static_cast<std::size_t>(z) * count.y + y) * count.x + x];
  };
  // Forward over the 13 neighbours before a cell in raster order, then
  // backward over the 13 after it.
  for (int pass : {1, -1}) {
    const int z0 = pass > 0 ? 0 : count.z - 1, y0 = pass > 0 ? 0 : count.y - 1,
              x0 = pass > 0 ? 0 : count.x - 1;
    for (int z = z0; z >= 0 && z < count.z; z += pass) {
      for (int y = y0; y >= 0 && y < count.y; y += pass) {
        for (int x = x0; x >= 0 && x < count.x; x += pass) {
          int& here = at(x, y, z);
          for (int dz = -1; dz <= 0; ++dz) {
            for (int dy = -1; dy <= 1; ++dy) {
              for (int dx = -1; dx <= 1; ++dx) {
                // Raster-earlier neighbours only (for this pass's direction).
                if (dz == 0 && (dy > 0 || (dy == 0 && dx >= 0))) continue;
                const int nx = x + pass * dx, ny = y + pass * dy, nz = z + pass * dz;
                if (nx < 0 || ny < 0 || nz < 0 || nx >= count.x || ny >= count.y || nz >= count.z) {
                  continue;
                }
                here = std::min(here, at(nx, ny, nz) + 1);
              }
            }
          }
        }
      }
    }
  }
  emptyDistance.resize(codes.size());
  for (std::size_t b = 0; b < d.size(); ++b) {
    emptyDistance[b] = static_cast<std::uint8_t>(std::min(d[b], 255));
  }
}

std::uint8_t StepGrid::aheadCode(glm::ivec3 cell) const {
  std::uint8_t lowest = 255;
  for (int a = 0; a < 3; ++a) {
    for (int side : {-1, 1}) {
      glm::ivec3 n = cell;
      n[a] += side;
      lowest = contains(n) ? std::min(lowest, code(n)) : std::uint8_t{0};
      if (lowest == 0) return 0;
    }
  }
  return lowest;
}

std::vector<std::uint8_t> classifyStepBlocks(const std::vector<float>& mins,
                                             const std::vector<float>& maxs, ValueRange window,
                                             const TransferFunction& tf, double opacityScale,
                                             double sampleDistance, int tableEntries,
                                             const Sampling& sampling, bool adaptive) {
  if (mins.size() != maxs.size()) throw Error("step blocks: minima and maxima differ in count");
  if (tableEntries < 2) throw Error("step blocks: a table has at least 2 entries");
  const int maxM = sampling.maxMultiplier;
  if (adaptive && (maxM < 1 || maxM > 64 || (maxM & (maxM - 1)) != 0)) {
    throw InputError(
        "adaptive sampling: the largest step multiplier must be a power of two in "
        "1..64, got " +
        std::to_string(maxM));
  }
  if (adaptive && !(sampling.tolerance >= 0.0)) {
    throw InputError("adaptive sampling: the tolerance must be >= 0");
  }
  // tau and tau * colour at R + 1 points: the variation of a block is read
  // off these (a heuristic bound; the widening below keeps it conservative).
  constexpr int kR = 1024;
  std::vector<double> tau(kR + 1), er(kR + 1), eg(kR + 1), eb(kR + 1);
  for (int i = 0; i <= kR; ++i) {
    const double x = static_cast<double>(i) / kR;
    const double a0 = std::clamp(tf.opacity(x) * opacityScale, 0.0, 1.0 - 1e-9);
    const double t = -std::log1p(-a0) / tf.opacityUnitLength;
    const glm::dvec3 c = tf.color(x);
    tau[static_cast<std::size_t>(i)] = t;
    er[static_cast<std::size_t>(i)] = t * c.r;
    eg[static_cast<std::size_t>(i)] = t * c.g;
    eb[static_cast<std::size_t>(i)] = t * c.b;
  }
  const RangeExtremes rTau(tau), rR(er), rG(eg), rB(eb);
  const double ww = window.max - window.min;
  const double n1 = tableEntries - 1;
  // The code of a block whose values mix table cells lo..hi (normalised).
  const auto classifyCells = [&](double lo, double hi) -> std::uint8_t {
    if (maxOpacity(tf, lo, hi) * opacityScale <= 0.0) return 0;
    if (!adaptive) return kUnitStepCode;
    const auto i0 = static_cast<std::size_t>(std::floor(lo * kR));
    const auto i1 =
        std::min(static_cast<std::size_t>(kR), static_cast<std::size_t>(std::ceil(hi * kR)));
    const double v =
        rTau.spread(i0, i1) + std::max({rR.spread(i0, i1), rG.spread(i0, i1), rB.spread(i0, i1)});
    // s = tolerance / (ds V), rounded down to an eighth of an octave.
    const double eighths =
        v > 0.0 ? std::floor(8.0 * std::log2(sampling.tolerance / (sampleDistance * v))) : 1000.0;
    return static_cast<std::uint8_t>(std::clamp(64.0 + eighths, 1.0, 255.0));
  };
  std::vector<std::uint8_t> codes(mins.size());
  // A block's code depends only on the table cells it mixes: blocks share
  // few pairs of them (those of one value range), so each pair is
  // classified once.
  std::unordered_map<std::uint32_t, std::uint8_t> codeOfCells;
  for (std::size_t b = 0; b < mins.size(); ++b) {
    const double nlo = std::clamp((mins[b] - window.min) / ww, 0.0, 1.0);
    const double nhi = std::clamp((maxs[b] - window.min) / ww, 0.0, 1.0);
    // The table cells a linear lookup of these values mixes.
    const double cellLo = std::floor(nlo * n1);
    const double cellHi = std::min(n1, std::ceil(nhi * n1));
    const auto cells =
        static_cast<std::uint32_t>(cellLo) * static_cast<std::uint32_t>(tableEntries) +
        static_cast<std::uint32_t>(cellHi);
    const auto [known, first] = codeOfCells.try_emplace(cells, std::uint8_t{0});
    if (first) known->second = classifyCells(cellLo / n1, cellHi / n1);
    codes[b] = known->second;
  }
  return codes;
}

}  // namespace tessera
