// Grid view navigation (Schultz 2016 §7.3): classification of every grid
// point, legal moves at every class, the block of cells around a point,
// and moves from the view direction.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include <glm/geometric.hpp>

#include "tessera/core/Camera.h"
#include "tessera/core/Error.h"
#include "tessera/lod/GridNavigator.h"

using namespace tessera;
using namespace tessera::lod;

namespace {

int boundaryAxes(glm::ivec3 p, glm::ivec3 cells) {
  int n = 0;
  for (int a = 0; a < 3; ++a) n += (p[a] == 0 || p[a] == cells[a]) ? 1 : 0;
  return n;
}

}  // namespace

TEST(GridNavigator, PaperSplitOfTheDogHeadHasFiveCubedPoints) {
  const GridNavigator g = GridNavigator::splitInto({512, 512, 894}, glm::ivec3(4));
  EXPECT_EQ(g.cells(), glm::ivec3(4));
  EXPECT_EQ(g.points(), glm::ivec3(5));
  EXPECT_EQ(g.cellSize(), glm::ivec3(128, 128, 224));
  // The paper numbers points x fastest: the last is 124.
  EXPECT_EQ(g.pointNumber({0, 0, 0}), 0);
  EXPECT_EQ(g.pointNumber({4, 4, 4}), 124);
  EXPECT_EQ(g.pointNumber({0, 0, 1}), 25);
  EXPECT_EQ(g.point(), glm::ivec3(2));  // starts in the middle
  // The 2x2x2 block around the centre point: half the volume per axis.
  const VoxelBox b = g.blockBox(g.point());
  EXPECT_EQ(b.begin, glm::ivec3(128, 128, 224));
  EXPECT_EQ(b.end, glm::ivec3(384, 384, 672));
  EXPECT_EQ(g.blockCells(g.point()).size(), 8u);
}

TEST(GridNavigator, ClassifiesEveryPointByItsBoundaryAxes) {
  const GridNavigator g({100, 70, 50}, {25, 25, 25});  // 4 x 3 x 2 cells
  ASSERT_EQ(g.cells(), glm::ivec3(4, 3, 2));
  int counts[4] = {0, 0, 0, 0};
  for (int z = 0; z <= 2; ++z) {
    for (int y = 0; y <= 3; ++y) {
      for (int x = 0; x <= 4; ++x) {
        const glm::ivec3 p(x, y, z);
        const GridPointClass c = g.classify(p);
        const int b = boundaryAxes(p, g.cells());
        const GridPointClass expected = b == 3   ? GridPointClass::Corner
                                        : b == 2 ? GridPointClass::Edge
                                        : b == 1 ? GridPointClass::Face
                                                 : GridPointClass::Interior;
        EXPECT_EQ(c, expected) << g.describe(p);
        ++counts[b];
      }
    }
  }
  // 5 x 4 x 3 points: 8 corners; edges along x, y, z hold 3, 2, 1 inner
  // points each, four edges per axis; 3 x 2 x 1 interior points.
  EXPECT_EQ(counts[3], 8);
  EXPECT_EQ(counts[0], 3 * 2 * 1);
  EXPECT_EQ(counts[2], 4 * (3 + 2 + 1));
  EXPECT_EQ(counts[0] + counts[1] + counts[2] + counts[3], 5 * 4 * 3);
  EXPECT_EQ(g.describe({0, 3, 1}), "edge (-x, +y) at (0, 3, 1) of (4, 3, 2)");
  EXPECT_EQ(g.describe({2, 1, 1}), "interior at (2, 1, 1) of (4, 3, 2)");
}

TEST(GridNavigator, LegalMovesAtEveryClassStayOnTheGrid) {
  const GridNavigator g({100, 70, 50}, {25, 25, 25});
  std::set<GridPointClass> seen;
  for (int z = 0; z <= 2; ++z) {
    for (int y = 0; y <= 3; ++y) {
      for (int x = 0; x <= 4; ++x) {
        const glm::ivec3 p(x, y, z);
        seen.insert(g.classify(p));
        const std::vector<GridMove> legal = g.legalMoves(p);
        // Each boundary coordinate forbids exactly the move off the grid:
        // corner 3 moves, edge 4, face 5, interior 6.
        EXPECT_EQ(legal.size(), 6u - static_cast<unsigned>(boundaryAxes(p, g.cells())))
            << g.describe(p);
        for (int a = 0; a < 3; ++a) {
          for (int sign : {1, -1}) {
            const MoveResult r = g.check(p, {a, sign});
            const int to = p[a] + sign;
            EXPECT_EQ(r.moved, to >= 0 && to <= g.cells()[a]) << g.describe(p);
            EXPECT_EQ(r.reason.empty(), r.moved);
          }
        }
      }
    }
  }
  EXPECT_EQ(seen.size(), 4u);
}

TEST(GridNavigator, RefusedMoveSaysWhyAndStays) {
  GridNavigator g({100, 70, 50}, {25, 25, 25});
  g.moveTo({4, 0, 2});  // corner +x -y +z
  EXPECT_EQ(g.pointClass(), GridPointClass::Corner);
  MoveResult r = g.apply({0, 1});
  EXPECT_FALSE(r.moved);
  EXPECT_EQ(r.reason, "cannot move +x: at the +x face of the grid (x = 4 of 0..4)");
  EXPECT_EQ(g.point(), glm::ivec3(4, 0, 2));
  r = g.apply({1, -1});
  EXPECT_FALSE(r.moved);
  EXPECT_NE(r.reason.find("-y face"), std::string::npos);
  r = g.apply({0, -1});
  EXPECT_TRUE(r.moved);
  EXPECT_EQ(g.point(), glm::ivec3(3, 0, 2));
  EXPECT_EQ(g.pointClass(), GridPointClass::Edge);
  EXPECT_THROW(g.moveTo({5, 0, 0}), InputError);
}

TEST(GridNavigator, BlocksShareFourCellsAfterEveryMove) {
  const GridNavigator g = GridNavigator::splitInto({512, 512, 894}, glm::ivec3(4));
  for (int a = 0; a < 3; ++a) {
    const glm::ivec3 p(2);
    glm::ivec3 q = p;
    q[a] += 1;
    const auto before = g.blockCells(p), after = g.blockCells(q);
    int shared = 0;
    for (const glm::ivec3& c : before) {
      for (const glm::ivec3& d : after) shared += c == d ? 1 : 0;
    }
    EXPECT_EQ(shared, 4);
  }
  // Boundary blocks hold fewer cells: corner 1, edge 2, face 4.
  EXPECT_EQ(g.blockCells({0, 0, 0}).size(), 1u);
  EXPECT_EQ(g.blockCells({0, 0, 2}).size(), 2u);
  EXPECT_EQ(g.blockCells({0, 2, 2}).size(), 4u);
  // The block box is exactly the union of its cells.
  for (const glm::ivec3 p : {glm::ivec3(0), glm::ivec3(4), glm::ivec3(1, 4, 3)}) {
    const VoxelBox box = g.blockBox(p);
    std::uint64_t sum = 0;
    for (const glm::ivec3& c : g.blockCells(p)) sum += g.cellBox(c).count();
    EXPECT_EQ(box.count(), sum);
  }
  EXPECT_EQ(g.blockBox({4, 4, 4}).end, glm::ivec3(512, 512, 894));
}

TEST(GridNavigator, ForBudgetKeepsTheBlockWithinTheVoxelBudget) {
  const GridNavigator g = GridNavigator::forBudget({512, 512, 894}, 256ull * 256 * 256, 32);
  EXPECT_EQ(g.cellSize(), glm::ivec3(128));
  EXPECT_LE(g.blockBox(g.point()).count(), 256ull * 256 * 256);
  // A small budget still gets one brick-sized cell.
  EXPECT_EQ(GridNavigator::forBudget({64, 64, 64}, 10, 32).cellSize(), glm::ivec3(32));
  EXPECT_THROW(GridNavigator({0, 4, 4}, {2, 2, 2}), InputError);
}

TEST(GridNavigator, ForwardIsTheDominantAxisOfTheViewDirection) {
  EXPECT_EQ(dominantAxis({0.1, -0.9, 0.3}), (GridMove{1, -1}));
  EXPECT_EQ(dominantAxis({0.6, 0.5, -0.62}), (GridMove{2, -1}));
  // Camera from the front (azimuth 0) of a RAS volume looks along -y
  // (anterior to posterior); right on screen is the patient's left (-x),
  // up is superior (+z).
  Camera cam;
  cam.frame(glm::dvec3(100.0));
  const glm::dmat3 b = cam.basis();
  EXPECT_EQ(viewMoveToGridMove(b, ViewMove::Forward), (GridMove{1, -1}));
  EXPECT_EQ(viewMoveToGridMove(b, ViewMove::Back), (GridMove{1, 1}));
  EXPECT_EQ(viewMoveToGridMove(b, ViewMove::Right), (GridMove{0, -1}));
  EXPECT_EQ(viewMoveToGridMove(b, ViewMove::Up), (GridMove{2, 1}));
  EXPECT_EQ(viewMoveToGridMove(b, ViewMove::Down), (GridMove{2, -1}));
  // Every camera orientation gives three different axes.
  for (double az = -180.0; az < 180.0; az += 7.5) {
    for (double el = -85.0; el <= 85.0; el += 8.5) {
      cam.azimuthDeg = az;
      cam.elevationDeg = el;
      const glm::dmat3 basis = cam.basis();
      const int f = viewMoveToGridMove(basis, ViewMove::Forward).axis;
      const int r = viewMoveToGridMove(basis, ViewMove::Right).axis;
      const int u = viewMoveToGridMove(basis, ViewMove::Up).axis;
      EXPECT_NE(f, r);
      EXPECT_NE(f, u);
      EXPECT_NE(r, u);
      // Forward never goes against the view direction.
      const GridMove fm = viewMoveToGridMove(basis, ViewMove::Forward);
      EXPECT_GT(glm::dot(glm::dvec3(fm.step()), -basis[2]), 0.0);
    }
  }
}

TEST(GridNavigator, PaperThresholdsGiveDiagonalsTheDominantAxisDoesNot) {
  EXPECT_EQ(paperStep({1, 0, 0}), glm::ivec3(1, 0, 0));
  EXPECT_EQ(paperStep({0, 0, -1}), glm::ivec3(0, 0, -1));
  EXPECT_EQ(paperStep({0, -1, 0}), glm::ivec3(0, -1, 0));
  // 45 degrees in the x-z plane: the paper steps along x and z at once.
  const glm::dvec3 d = glm::normalize(glm::dvec3(1, 0, 1));
  EXPECT_EQ(paperStep(d), glm::ivec3(1, 0, 1));
  EXPECT_EQ(dominantAxis(d + glm::dvec3(1e-9, 0, 0)).step(), glm::ivec3(1, 0, 0));
  // Its bands are not symmetric in x and y: 45 degrees in the x-y plane
  // steps in x and y; 30 degrees off +x already steps in y too.
  EXPECT_EQ(paperStep(glm::normalize(glm::dvec3(1, 1, 0))), glm::ivec3(1, 1, 0));
  EXPECT_EQ(paperStep({std::cos(0.52), std::sin(0.52), 0}), glm::ivec3(1, 1, 0));
}
