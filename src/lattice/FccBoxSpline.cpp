#include "tessera/lattice/FccBoxSpline.h"

#include <algorithm>
#include <cmath>

#include "lattice/FccBoxSplinePieces.h"

namespace tessera::lattice {

namespace {

using detail::BoxSplinePiece;

const BoxSplinePiece& pieceOf(BoxSplineStencil::Piece piece) {
  return piece == BoxSplineStencil::Piece::Corner ? detail::kCornerPiece : detail::kCentralPiece;
}

// Which reflection pair (x and y, x and z, y and z) carries the corner
// tetrahedron at w's even corner onto the one at the origin; none and
// Central for the central tetrahedron. w: local coordinates in a cube whose
// lower corner is a lattice point (Sarfaraz & Shaban 2015, 4.3, after Kim 2013).
BoxSplineStencil::Piece classify(glm::dvec3 w, glm::bvec3& reflect) {
  reflect = glm::bvec3(false);
  if (w.x + w.y + w.z <= 1.0) return BoxSplineStencil::Piece::Corner;  // corner (0,0,0)
  if (w.x + w.y - w.z >= 1.0) {
    reflect = {true, true, false};  // corner (1,1,0)
  } else if (w.x - w.y + w.z >= 1.0) {
    reflect = {true, false, true};  // corner (1,0,1)
  } else if (-w.x + w.y + w.z >= 1.0) {
    reflect = {false, true, true};  // corner (0,1,1)
  } else {
    return BoxSplineStencil::Piece::Central;
  }
  return BoxSplineStencil::Piece::Corner;
}

// x^0..x^3 for each axis.
struct Powers {
  std::array<double, 4> p[3];
  explicit Powers(glm::dvec3 v) {
    for (int a = 0; a < 3; ++a) p[a] = {1.0, v[a], v[a] * v[a], v[a] * v[a] * v[a]};
  }
};

}  // namespace

BoxSplineStencil locateBoxSpline(glm::dvec3 u) {
  const glm::dvec3 floorU = glm::floor(u);
  const glm::ivec3 o(floorU);
  const glm::dvec3 v = u - floorU;
  // A cube with an odd lower corner is the point reflection v -> 1 - v of
  // an even one (K is symmetric, and the reflection maps FCC onto itself).
  const bool odd = ((o.x + o.y + o.z) & 1) != 0;
  BoxSplineStencil s;
  glm::bvec3 reflect;
  s.piece = classify(odd ? 1.0 - v : v, reflect);
  glm::ivec3 base;
  for (int a = 0; a < 3; ++a) {
    // Both reflections together: lattice point = base + sign * offset.
    const bool flip = odd != reflect[a];
    base[a] = o[a] + (flip ? 1 : 0);
    s.sign[a] = flip ? -1 : 1;
    s.local[a] = flip ? 1.0 - v[a] : v[a];
  }
  const BoxSplinePiece& piece = pieceOf(s.piece);
  for (int k = 0; k < kBoxSplineStencilSize; ++k) {
    const auto& off = piece[static_cast<std::size_t>(k)].lattice;
    s.points[static_cast<std::size_t>(k)] = base + s.sign * glm::ivec3(off[0], off[1], off[2]);
  }
  return s;
}

BoxSplineSample evaluateBoxSpline(const BoxSplineStencil& stencil,
                                  const std::array<double, kBoxSplineStencilSize>& coefficients) {
  const BoxSplinePiece& piece = pieceOf(stencil.piece);
  // The piece's cubic for these coefficients, in monomial form.
  std::array<double, detail::kPieceMonomials> poly{};
  for (std::size_t k = 0; k < piece.size(); ++k) {
    for (std::size_t m = 0; m < poly.size(); ++m) {
      poly[m] += coefficients[k] * piece[k].coefficient[m];
    }
  }
  const Powers pw(stencil.local);
  BoxSplineSample out;
  glm::dvec3 g(0.0);
  for (std::size_t m = 0; m < poly.size(); ++m) {
    const auto& e = detail::kPieceExponents[m];
    const double px = pw.p[0][e[0]], py = pw.p[1][e[1]], pz = pw.p[2][e[2]];
    out.value += poly[m] * px * py * pz;
    if (e[0] > 0) g.x += poly[m] * e[0] * pw.p[0][e[0] - 1] * py * pz;
    if (e[1] > 0) g.y += poly[m] * e[1] * px * pw.p[1][e[1] - 1] * pz;
    if (e[2] > 0) g.z += poly[m] * e[2] * px * py * pw.p[2][e[2] - 1];
  }
  constexpr double kScale = 1.0 / detail::kPieceDenominator;
  out.value *= kScale;
  out.gradient = glm::dvec3(stencil.sign) * g * kScale;
  return out;
}

BoxSplineSample boxSplineKernel(glm::dvec3 x) {
  const BoxSplineStencil s = locateBoxSpline(x);
  std::array<double, kBoxSplineStencilSize> unit{};
  const auto it = std::find(s.points.begin(), s.points.end(), glm::ivec3(0));
  if (it == s.points.end()) return {};
  unit[static_cast<std::size_t>(it - s.points.begin())] = 1.0;
  return evaluateBoxSpline(s, unit);
}

FccBoxSpline::FccBoxSpline(const FccVolume& volume)
    : grid_(volume.gridDims()), packed_(volume.packed().dims()) {
  const Volume& p = volume.packed();
  texels_.resize(static_cast<std::size_t>(p.voxelCount()));
  for (std::size_t i = 0; i < texels_.size(); ++i) texels_[i] = p.finiteValueAtIndex(i);
}

std::array<double, kBoxSplineStencilSize> FccBoxSpline::gather(
    const BoxSplineStencil& stencil) const {
  std::array<double, kBoxSplineStencilSize> c;
  for (std::size_t k = 0; k < c.size(); ++k) {
    const glm::ivec3 t = FccVolume::clampedTexel(stencil.points[k], grid_);
    c[k] = texels_[(static_cast<std::size_t>(t.z) * packed_.y + t.y) * packed_.x + t.x];
  }
  return c;
}

double FccBoxSpline::value(glm::dvec3 u) const {
  return sample(u).value;
}

BoxSplineSample FccBoxSpline::sample(glm::dvec3 u) const {
  const BoxSplineStencil s = locateBoxSpline(u);
  return evaluateBoxSpline(s, gather(s));
}

}  // namespace tessera::lattice
