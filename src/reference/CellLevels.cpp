#include "tessera/reference/CellLevels.h"

#include <algorithm>

#include <glm/common.hpp>

#include "tessera/reference/ReferenceRaycaster.h"

namespace tessera {

int CellLevels::levelAt(glm::dvec3 p) const {
  const glm::dvec3 x0 = glm::clamp(p, 0.0, 1.0) * glm::dvec3(finestDims);
  const glm::ivec3 c =
      glm::min(glm::ivec3(glm::floor(x0 / static_cast<double>(brickSize))), cells - 1);
  return levels[(static_cast<std::size_t>(c.z) * cells.y + c.y) * cells.x +
                static_cast<std::size_t>(c.x)];
}

std::vector<int> CellLevels::cellsPerLevel() const {
  const int top = levels.empty() ? 0 : *std::max_element(levels.begin(), levels.end());
  std::vector<int> out(static_cast<std::size_t>(top) + 2, 0);
  for (int l : levels) ++out[l < 0 ? out.size() - 1 : static_cast<std::size_t>(l)];
  return out;
}

bool CellLevels::mixed() const {
  const std::vector<int> n = cellsPerLevel();
  return std::count_if(n.begin(), n.end() - 1, [](int c) { return c > 0; }) > 1;
}

double sampleLevel(const Volume& level, glm::ivec3 scale, glm::ivec3 finestDims, glm::dvec3 p) {
  // Texture space of level 0's box -> the level's: p finestDims / scale is
  // the level coordinate, over its dims.
  const glm::dvec3 toLevel =
      glm::dvec3(finestDims) / (glm::dvec3(level.dims()) * glm::dvec3(scale));
  return sampleTrilinear(level, glm::clamp(p, 0.0, 1.0) * toLevel);
}

}  // namespace tessera
