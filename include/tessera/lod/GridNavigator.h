#pragma once
// Grid view over a large volume (Schultz 2016 §7.3): the finest level is
// split into cells (sub-volumes, e.g. 4x4x4 cells of 128x128x224 voxels for
// a 512x512x894 volume) and the user stands on a grid point, a cell corner;
// the cells around it (the 2x2x2 block whose common corner the point is, so
// at most eight, fewer on the boundary) are read at native resolution and
// rendered. Moving one grid point along an axis keeps half of the block
// (four cells), which is what lets the user keep their bearings.
//
// Grid points run 0..cells[a] along each axis (one more than the cells), so
// a volume that is one cell thick along an axis still has points on both
// faces. A point is a corner, edge, face or interior point by how many of
// its coordinates sit on the grid's boundary (3, 2, 1 or 0); each boundary
// coordinate forbids exactly one of the six axis moves.
//
// Moves from the view direction. The paper turns the view vector into
// spherical angles and uses overlapping theta/phi bands (67.5/112.5 deg for
// z and x, 22.5/157.5 deg for y), which can step along two or three axes at
// once and treats z (the pole) differently from x and y. We use the
// dominant axis instead: "forward" is the index axis the view direction
// (expressed in the volume's index axes) has the largest component along,
// signed; "right" and "up" are the dominant axes of the screen's right and
// up vectors among the two remaining axes. This is the cube-face partition
// of the sphere of directions: symmetric in x, y and z, every direction gets
// exactly one axis, forward/right/up are always three different axes, and
// every step changes one coordinate, so consecutive blocks always share four
// cells. Diagonals are two key presses. paperStep() keeps the paper's rule
// for comparison.
#include <array>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "tessera/lod/MultiresSource.h"

namespace tessera::lod {

enum class GridPointClass { Corner, Edge, Face, Interior };
const char* gridPointClassName(GridPointClass c);

// One of the six axis moves: +x, -x, +y, -y, +z, -z.
struct GridMove {
  int axis = 0;  // 0, 1, 2: index axis x, y, z
  int sign = 1;  // +1 or -1
  glm::ivec3 step() const {
    glm::ivec3 s(0);
    s[axis] = sign;
    return s;
  }
  std::string name() const;  // "+x", "-z"
  bool operator==(const GridMove&) const = default;
};

// The six screen-relative moves of the grid view's controls.
enum class ViewMove { Forward, Back, Left, Right, Up, Down };
const char* viewMoveName(ViewMove m);

struct MoveResult {
  bool moved = false;
  std::string reason;  // why not, e.g. "at the +x face of the grid (x = 4 of 0..4)"
};

class GridNavigator {
 public:
  // `dims`: level-0 voxels; `cellSize`: voxels per cell along each axis (the
  // last cell along an axis may be partial). InputError if any is < 1.
  GridNavigator(glm::ivec3 dims, glm::ivec3 cellSize);
  // The paper's split: `cells` cells along each axis, sized ceil(dims / cells).
  static GridNavigator splitInto(glm::ivec3 dims, glm::ivec3 cells);
  // Cubic cells of a multiple of `align` voxels (a brick size, so reads stay
  // on brick boundaries) as large as possible while a 2x2x2 block holds at
  // most `maxBlockVoxels` voxels; at least `align`.
  static GridNavigator forBudget(glm::ivec3 dims, std::uint64_t maxBlockVoxels, int align);

  glm::ivec3 dims() const { return dims_; }
  glm::ivec3 cellSize() const { return cell_; }
  glm::ivec3 cells() const { return cells_; }
  glm::ivec3 points() const { return cells_ + 1; }  // grid points per axis

  // The current grid point; starts at the point nearest the volume's centre.
  glm::ivec3 point() const { return point_; }
  // Linear number as the paper counts them: x fastest, then y, then z.
  int pointNumber(glm::ivec3 p) const;
  // InputError (naming the point and the grid) when outside 0..cells.
  void moveTo(glm::ivec3 p);

  GridPointClass classify(glm::ivec3 p) const;
  GridPointClass pointClass() const { return classify(point_); }
  // "edge (-x, +z) at (0, 2, 4)" for a status line.
  std::string describe(glm::ivec3 p) const;

  // Whether `move` from `p` stays on the grid; if not, why (for the UI).
  MoveResult check(glm::ivec3 p, GridMove move) const;
  std::vector<GridMove> legalMoves(glm::ivec3 p) const;
  // Moves the current point if legal; otherwise leaves it and says why.
  MoveResult apply(GridMove move);

  // The cells around `p` that exist (1, 2, 4 or 8): cells p - 1 .. p per
  // axis, clamped to the grid.
  std::vector<glm::ivec3> blockCells(glm::ivec3 p) const;
  // The level-0 voxels those cells cover: one bounded read.
  VoxelBox blockBox(glm::ivec3 p) const;
  VoxelBox cellBox(glm::ivec3 cell) const;

 private:
  glm::ivec3 dims_;
  glm::ivec3 cell_;
  glm::ivec3 cells_;
  glm::ivec3 point_;
};

// The grid move a screen-relative control means for a camera whose basis
// (columns: right, up, back) is given in the volume's index frame (model
// frame: axes along the index axes; Camera::basis()): Forward is the
// dominant axis of the view direction (-back), Right/Up the dominant of the
// other two axes for the screen's right/up; Back, Left, Down their opposites.
GridMove viewMoveToGridMove(const glm::dmat3& cameraBasis, ViewMove move);

// Index axis with the largest |component| (ties: the lower axis), and its sign.
GridMove dominantAxis(const glm::dvec3& direction);

// Schultz 2016 §7.3.6: the (possibly diagonal) step the paper takes for a
// unit view direction in index space, by theta = acos(z) and
// phi = atan2(y, x) with its overlapping bands. For comparison and tests.
glm::ivec3 paperStep(const glm::dvec3& direction);

}  // namespace tessera::lod
