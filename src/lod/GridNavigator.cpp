#include "tessera/lod/GridNavigator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "tessera/core/Error.h"

namespace tessera::lod {

namespace {

std::string pointText(glm::ivec3 p) {
  char text[64];
  std::snprintf(text, sizeof text, "(%d, %d, %d)", p.x, p.y, p.z);
  return text;
}

constexpr const char* kAxisNames = "xyz";

}  // namespace

const char* gridPointClassName(GridPointClass c) {
  switch (c) {
    case GridPointClass::Corner:
      return "corner";
    case GridPointClass::Edge:
      return "edge";
    case GridPointClass::Face:
      return "face";
    case GridPointClass::Interior:
      return "interior";
  }
  return "?";
}

const char* viewMoveName(ViewMove m) {
  switch (m) {
    case ViewMove::Forward:
      return "forward";
    case ViewMove::Back:
      return "back";
    case ViewMove::Left:
      return "left";
    case ViewMove::Right:
      return "right";
    case ViewMove::Up:
      return "up";
    case ViewMove::Down:
      return "down";
  }
  return "?";
}

std::string GridMove::name() const {
  return std::string(sign > 0 ? "+" : "-") + kAxisNames[axis];
}

GridNavigator::GridNavigator(glm::ivec3 dims, glm::ivec3 cellSize) : dims_(dims), cell_(cellSize) {
  for (int a = 0; a < 3; ++a) {
    if (dims[a] < 1 || cellSize[a] < 1) {
      throw InputError("grid view: volume " + pointText(dims) + " and cell size " +
                       pointText(cellSize) + " must be at least 1 voxel along every axis");
    }
    cell_[a] = std::min(cellSize[a], dims[a]);
  }
  cells_ = (dims_ + cell_ - 1) / cell_;
  // The point nearest the centre: the middle of 0..cells.
  point_ = (cells_ + 1) / 2;
}

GridNavigator GridNavigator::splitInto(glm::ivec3 dims, glm::ivec3 cells) {
  for (int a = 0; a < 3; ++a) {
    if (cells[a] < 1) throw InputError("grid view: need at least one cell along every axis");
  }
  return GridNavigator(dims, (dims + cells - 1) / cells);
}

GridNavigator GridNavigator::forBudget(glm::ivec3 dims, std::uint64_t maxBlockVoxels, int align) {
  if (align < 1) throw InputError("grid view: brick alignment must be at least 1 voxel");
  // A 2x2x2 block of cubic cells of side s holds at most (2s)^3 voxels,
  // fewer where the volume is thinner than 2s.
  auto blockVoxels = [&](int s) {
    std::uint64_t n = 1;
    for (int a = 0; a < 3; ++a) n *= static_cast<std::uint64_t>(std::min(2 * s, dims[a]));
    return n;
  };
  const int longest = std::max({dims.x, dims.y, dims.z});
  int side = align;
  while (side < longest && blockVoxels(side + align) <= maxBlockVoxels) side += align;
  return GridNavigator(dims, glm::ivec3(side));
}

int GridNavigator::pointNumber(glm::ivec3 p) const {
  const glm::ivec3 n = points();
  return p.x + n.x * (p.y + n.y * p.z);
}

void GridNavigator::moveTo(glm::ivec3 p) {
  for (int a = 0; a < 3; ++a) {
    if (p[a] < 0 || p[a] > cells_[a]) {
      throw InputError("grid point " + pointText(p) + " is outside the grid 0.." +
                       std::to_string(cells_.x) + " x 0.." + std::to_string(cells_.y) + " x 0.." +
                       std::to_string(cells_.z));
    }
  }
  point_ = p;
}

GridPointClass GridNavigator::classify(glm::ivec3 p) const {
  int boundary = 0;
  for (int a = 0; a < 3; ++a) boundary += (p[a] == 0 || p[a] == cells_[a]) ? 1 : 0;
  static constexpr GridPointClass kByBoundaryAxes[4] = {
      GridPointClass::Interior, GridPointClass::Face, GridPointClass::Edge, GridPointClass::Corner};
  return kByBoundaryAxes[boundary];
}

std::string GridNavigator::describe(glm::ivec3 p) const {
  std::string sides;
  for (int a = 0; a < 3; ++a) {
    if (p[a] != 0 && p[a] != cells_[a]) continue;
    if (!sides.empty()) sides += ", ";
    sides += std::string(p[a] == 0 ? "-" : "+") + kAxisNames[a];
  }
  std::string s = gridPointClassName(classify(p));
  if (!sides.empty()) s += " (" + sides + ")";
  return s + " at " + pointText(p) + " of " + pointText(cells_);
}

MoveResult GridNavigator::check(glm::ivec3 p, GridMove move) const {
  const int to = p[move.axis] + move.sign;
  if (to >= 0 && to <= cells_[move.axis]) return {true, ""};
  const char axis = kAxisNames[move.axis];
  return {false, "cannot move " + move.name() + ": at the " + (move.sign > 0 ? "+" : "-") + axis +
                     " face of the grid (" + axis + " = " + std::to_string(p[move.axis]) +
                     " of 0.." + std::to_string(cells_[move.axis]) + ")"};
}

std::vector<GridMove> GridNavigator::legalMoves(glm::ivec3 p) const {
  std::vector<GridMove> moves;
  for (int a = 0; a < 3; ++a) {
    for (int sign : {1, -1}) {
      if (check(p, {a, sign}).moved) moves.push_back({a, sign});
    }
  }
  return moves;
}

MoveResult GridNavigator::apply(GridMove move) {
  MoveResult r = check(point_, move);
  if (r.moved) point_ += move.step();
  return r;
}

std::vector<glm::ivec3> GridNavigator::blockCells(glm::ivec3 p) const {
  std::vector<glm::ivec3> out;
  for (int z = p.z - 1; z <= p.z; ++z) {
    for (int y = p.y - 1; y <= p.y; ++y) {
      for (int x = p.x - 1; x <= p.x; ++x) {
        const glm::ivec3 c(x, y, z);
        if (glm::all(glm::greaterThanEqual(c, glm::ivec3(0))) &&
            glm::all(glm::lessThan(c, cells_))) {
          out.push_back(c);
        }
      }
    }
  }
  return out;
}

VoxelBox GridNavigator::cellBox(glm::ivec3 cell) const {
  return {cell * cell_, glm::min((cell + 1) * cell_, dims_)};
}

VoxelBox GridNavigator::blockBox(glm::ivec3 p) const {
  const glm::ivec3 lo = glm::max(p - 1, glm::ivec3(0));
  const glm::ivec3 hi = glm::min(p, cells_ - 1);
  return {lo * cell_, glm::min((hi + 1) * cell_, dims_)};
}

GridMove dominantAxis(const glm::dvec3& d) {
  int axis = 0;
  for (int a = 1; a < 3; ++a) {
    if (std::abs(d[a]) > std::abs(d[axis])) axis = a;
  }
  return {axis, d[axis] < 0.0 ? -1 : 1};
}

GridMove viewMoveToGridMove(const glm::dmat3& basis, ViewMove move) {
  const GridMove forward = dominantAxis(-basis[2]);
  // Right: the dominant of the two axes forward does not use.
  glm::dvec3 r = basis[0];
  r[forward.axis] = 0.0;
  const GridMove right = dominantAxis(r);
  glm::dvec3 u = basis[1];
  u[forward.axis] = 0.0;
  u[right.axis] = 0.0;
  const GridMove up = dominantAxis(u);
  auto opposite = [](GridMove m) { return GridMove{m.axis, -m.sign}; };
  switch (move) {
    case ViewMove::Forward:
      return forward;
    case ViewMove::Back:
      return opposite(forward);
    case ViewMove::Right:
      return right;
    case ViewMove::Left:
      return opposite(right);
    case ViewMove::Up:
      return up;
    case ViewMove::Down:
      return opposite(up);
  }
  return forward;
}

glm::ivec3 paperStep(const glm::dvec3& direction) {
  const glm::dvec3 d =
      glm::length(direction) > 0.0 ? direction / glm::length(direction) : direction;
  const double deg = 180.0 / 3.14159265358979323846;
  const double theta = std::acos(std::clamp(d.z, -1.0, 1.0)) * deg;
  const double phi = std::atan2(d.y, d.x) * deg;
  glm::ivec3 step(0);
  if (theta < 67.5) step.z = 1;
  if (theta > 112.5) step.z = -1;
  // The band in which x and y count, as printed (27.5 below, 157.5 above).
  if (theta > 27.5 && theta < 157.5) {
    const double a = std::abs(phi);
    if (a < 67.5) step.x = 1;
    if (a > 112.5) step.x = -1;
    if (a > 22.5 && a < 157.5) step.y = phi > 0.0 ? 1 : -1;
  }
  return step;
}

}  // namespace tessera::lod
