#include "tessera/reference/CellLevels.h"

#include <algorithm>
#include <string>
#include <utility>

#include <glm/common.hpp>

#include "tessera/core/Error.h"
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

CellLevelsReconstruction::CellLevelsReconstruction(
    CellLevels cells, std::vector<std::shared_ptr<const Reconstruction>> levels,
    int transparentLevel)
    : cells_(std::move(cells)), levels_(std::move(levels)), transparentLevel_(transparentLevel) {
  const std::size_t expected = static_cast<std::size_t>(cells_.cells.x) * cells_.cells.y *
                               static_cast<std::size_t>(cells_.cells.z);
  if (cells_.brickSize < 1 || cells_.levels.size() != expected) {
    throw InputError("cell levels: " + std::to_string(cells_.levels.size()) +
                     " cells, the grid has " + std::to_string(expected));
  }
  const std::vector<int> n = cells_.cellsPerLevel();
  const auto held = [&](std::size_t l) { return l < levels_.size() && levels_[l]; };
  for (std::size_t l = 0; l + 1 < n.size(); ++l) {
    if (n[l] > 0 && !held(l)) {
      throw InputError("cell levels: " + std::to_string(n[l]) + " cells show level " +
                       std::to_string(l) + ", which is not read");
    }
  }
  if (n.back() > 0 &&
      (transparentLevel_ < 0 || !held(static_cast<std::size_t>(transparentLevel_)))) {
    throw InputError("cell levels: " + std::to_string(n.back()) + " transparent cells read level " +
                     std::to_string(transparentLevel_) + ", which is not read");
  }
  for (const auto& l : levels_) {
    if (l) support_ = std::max(support_, l->supportVoxels());
  }
}

double CellLevelsReconstruction::value(glm::dvec3 p) const {
  const int l = cells_.levelAt(p);
  return levels_[static_cast<std::size_t>(l < 0 ? transparentLevel_ : l)]->value(p);
}

}  // namespace tessera
