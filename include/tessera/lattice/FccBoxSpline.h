#pragma once
// Exact evaluation of the six-direction box spline on the FCC lattice:
//   s(u) = sum over lattice points j of c_j K(u - j),
// u in grid coordinates (FccVolume), K the box spline of the directions
// (1,+-1,0), (1,0,+-1), (0,1,+-1), centred on the origin and scaled by 2 so
// that its FCC shifts sum to 1 (Kim, Entezari & Peters, "Box spline
// reconstruction on the face-centered cubic lattice", IEEE TVCG 14(6), 2008).
//
// Properties (all tested): K is a piecewise cubic and C1, not C2: across a
// knot plane its smoothness is #(directions off the plane) - 2 (de Boor,
// Hoellig & Riemenschneider, "Box Splines", 1993), so C2 across the axis
// planes but only C1 across the x +- y +- z planes, which hold three of the six
// directions. Its support is the truncated octahedron |x|_inf <= 2,
// |x|_1 <= 3; its second moment is I/3 per axis. The spline space holds every
// quadratic (approximation order 3): the samples themselves reproduce every
// linear function, a quadratic q comes back as q + laplacian(q) / 6, and
// quasiInterpolate() (FccResampling.h) removes that term.
//
// Evaluation (organised as in Kim, "GPU isosurface raycasting of FCC
// datasets", Graphical Models 75(2), 2013): the knot planes x, y, z in Z and
// x +- y +- z odd cut the unit cube around u into five tetrahedra; a cube with
// an odd lower corner is the point reflection of one with an even corner, and
// reflections of two axes map each of the four corner tetrahedra onto the
// one at the origin. So two reference pieces (corner and central), each a
// set of 16 cubics in the cube's local coordinates, give every value: 16
// lattice points (the minimal number) per sample. The cubics are derived
// exactly by src/lattice/derive_fcc_box_spline.py.
//
// A GPU twin does the same per sample: floor and parity of u, four plane
// tests, 16 texelFetch (FccVolume.h's addressing and boundary rule) and the
// two tables of src/lattice/FccBoxSplinePieces.h (small integers / 24) as
// const arrays; sign and local give the gradient for free.
#include <array>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/lattice/FccVolume.h"

namespace tessera::lattice {

inline constexpr int kBoxSplineStencilSize = 16;

// Where u's polynomial piece takes its data from.
struct BoxSplineStencil {
  enum class Piece { Corner, Central };
  Piece piece = Piece::Corner;
  // u in the reference piece's cube coordinates.
  glm::dvec3 local{0.0};
  // d/du = sign * d/dlocal (the symmetry that maps u's piece to the reference).
  glm::ivec3 sign{1};
  // The lattice points whose shifts of K cover u's piece.
  std::array<glm::ivec3, kBoxSplineStencilSize> points{};
};

struct BoxSplineSample {
  double value = 0.0;
  glm::dvec3 gradient{0.0};  // per grid unit
};

BoxSplineStencil locateBoxSpline(glm::dvec3 u);
// s(u) and its gradient from the coefficients of stencil.points, in order.
BoxSplineSample evaluateBoxSpline(const BoxSplineStencil& stencil,
                                  const std::array<double, kBoxSplineStencilSize>& coefficients);
// K(x) and its gradient, through the same pieces.
BoxSplineSample boxSplineKernel(glm::dvec3 x);

// The spline of an FccVolume's samples under its boundary rule.
class FccBoxSpline {
 public:
  explicit FccBoxSpline(const FccVolume& volume);
  double value(glm::dvec3 u) const;
  BoxSplineSample sample(glm::dvec3 u) const;
  glm::ivec3 gridDims() const { return grid_; }

 private:
  std::array<double, kBoxSplineStencilSize> gather(const BoxSplineStencil& stencil) const;

  glm::ivec3 grid_;
  glm::ivec3 packed_;
  std::vector<double> texels_;
};

}  // namespace tessera::lattice
