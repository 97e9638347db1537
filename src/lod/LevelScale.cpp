#include "tessera/lod/LevelScale.h"

#include <cmath>

#include "tessera/core/Error.h"

namespace tessera::lod {

namespace {

std::string dimsText(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

// The integer factor f with cur = ceil(prev / f) or floor(prev / f): the
// spacing's ratio where it is one of them, else 2 where it is one (the
// usual pyramid), else the smallest; 0 if none.
int stepFactor(int prev, int cur, double spacingRatio) {
  auto fits = [&](int f) { return cur == (prev + f - 1) / f || cur == prev / f; };
  const long bySpacing = std::lround(spacingRatio);
  if (bySpacing >= 1 && bySpacing <= prev &&
      std::abs(spacingRatio - bySpacing) < 0.01 * bySpacing && fits(static_cast<int>(bySpacing))) {
    return static_cast<int>(bySpacing);
  }
  if (fits(2)) return 2;
  for (int f = 1; f <= prev; ++f) {
    if (fits(f)) return f;
  }
  return 0;
}

}  // namespace

std::vector<glm::ivec3> levelFactors(const std::vector<LevelInfo>& levels,
                                     const std::string& what) {
  std::vector<glm::ivec3> out;
  for (std::size_t l = 0; l < levels.size(); ++l) {
    if (l == 0) {
      out.emplace_back(1);
      continue;
    }
    const LevelInfo& prev = levels[l - 1];
    const LevelInfo& cur = levels[l];
    glm::ivec3 f(1);
    for (int a = 0; a < 3; ++a) {
      const double ratio = prev.spacing[a] > 0.0f ? double(cur.spacing[a]) / prev.spacing[a] : 0.0;
      f[a] = stepFactor(prev.dims[a], cur.dims[a], ratio);
      if (f[a] == 0) {
        throw InputError(what + ": level " + std::to_string(l) + " (" + dimsText(cur.dims) +
                         ") does not reduce level " + std::to_string(l - 1) + " (" +
                         dimsText(prev.dims) + ") by an integer factor along " + "xyz"[a] +
                         "; the bricks layout streams pyramids whose levels keep or divide "
                         "each axis. Render it in core (--layout texture3d, or --region for a "
                         "part) or rewrite it with `tessera convert`");
      }
    }
    out.push_back(f);
  }
  return out;
}

std::vector<glm::ivec3> levelFactors(const MultiresSource& source) {
  std::vector<LevelInfo> levels;
  for (int l = 0; l < source.levelCount(); ++l) levels.push_back(source.levelInfo(l));
  return levelFactors(levels, source.describe());
}

std::vector<glm::ivec3> levelScales(const std::vector<glm::ivec3>& factors) {
  std::vector<glm::ivec3> out;
  glm::ivec3 s(1);
  for (glm::ivec3 f : factors) {
    s *= f;
    out.push_back(s);
  }
  return out;
}

glm::ivec3 levelScale(const MultiresSource& source, int level) {
  const std::vector<glm::ivec3> s = levelScales(levelFactors(source));
  if (level < 0 || level >= static_cast<int>(s.size())) {
    throw InputError("level " + std::to_string(level) + " of " + source.describe() +
                     ": the pyramid has levels 0.." + std::to_string(s.size() - 1));
  }
  return s[static_cast<std::size_t>(level)];
}

}  // namespace tessera::lod
