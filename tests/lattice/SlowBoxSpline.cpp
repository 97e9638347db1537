#include "lattice/SlowBoxSpline.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <glm/vec2.hpp>

namespace tessera::lattice::test {

namespace {

const std::array<glm::dvec3, 3> kA = {{{1, 1, 0}, {1, -1, 0}, {1, 0, 1}}};
const std::array<glm::dvec3, 3> kB = {{{1, 0, -1}, {0, 1, 1}, {0, 1, -1}}};
const glm::dvec3 kCentre(2, 1, 0);  // half the sum of all six directions

glm::dmat3 inverseB() {
  return glm::inverse(glm::dmat3(kB[0], kB[1], kB[2]));
}

using Polygon = std::vector<glm::dvec2>;

// The part of a convex polygon where n . p + a >= 0 (Sutherland-Hodgman).
Polygon clip(const Polygon& poly, glm::dvec2 n, double a) {
  Polygon out;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec2 p = poly[i], q = poly[(i + 1) % poly.size()];
    const double fp = n.x * p.x + n.y * p.y + a, fq = n.x * q.x + n.y * q.y + a;
    if (fp >= 0) out.push_back(p);
    if ((fp < 0 && fq > 0) || (fp > 0 && fq < 0)) out.push_back(p + (q - p) * (fp / (fp - fq)));
  }
  return out;
}

double area(const Polygon& poly) {
  double twice = 0.0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec2 p = poly[i], q = poly[(i + 1) % poly.size()];
    twice += p.x * q.y - q.x * p.y;
  }
  return std::abs(twice) / 2.0;
}

// area{(s, t) in [0,1]^2 : B^-1 (z - s a_i - t a_j) in [0,1]^3}, {i, j} the
// directions of A other than `skip`: 2 M_{Xi \ a_skip}(z).
double section(glm::dvec3 z, int skip) {
  static const glm::dmat3 bi = inverseB();
  const glm::dvec3 b = bi * z, p = bi * kA[static_cast<std::size_t>((skip + 1) % 3)],
                   q = bi * kA[static_cast<std::size_t>((skip + 2) % 3)];
  Polygon poly = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int r = 0; r < 3 && !poly.empty(); ++r) {
    poly = clip(poly, {-p[r], -q[r]}, b[r]);      // (B^-1 ...)_r >= 0
    poly = clip(poly, {p[r], q[r]}, 1.0 - b[r]);  // (B^-1 ...)_r <= 1
  }
  return poly.size() < 3 ? 0.0 : area(poly);
}

// t in (0,1) of every vertex candidate of the region {(t, s, r) in [0,1]^3 :
// B^-1 (z - t a1 - s a2 - r a3) in [0,1]^3}: intersections of three of its
// twelve bounding planes.
std::vector<double> breakpoints(glm::dvec3 z) {
  static const glm::dmat3 bi = inverseB();
  std::vector<glm::dvec3> normals;
  std::vector<double> offsets;
  for (int a = 0; a < 3; ++a) {
    glm::dvec3 n(0.0);
    n[a] = 1.0;
    normals.insert(normals.end(), {n, n});
    offsets.insert(offsets.end(), {0.0, 1.0});
  }
  const glm::dvec3 b = bi * z;
  for (int r = 0; r < 3; ++r) {
    const glm::dvec3 n((bi * kA[0])[r], (bi * kA[1])[r], (bi * kA[2])[r]);
    normals.insert(normals.end(), {n, n});
    offsets.insert(offsets.end(), {b[r], b[r] - 1.0});
  }
  std::vector<double> ts = {0.0, 1.0};
  const std::size_t n = normals.size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      for (std::size_t k = j + 1; k < n; ++k) {
        const glm::dmat3 m = glm::transpose(glm::dmat3(normals[i], normals[j], normals[k]));
        if (std::abs(glm::determinant(m)) < 1e-12) continue;
        const double t = (glm::inverse(m) * glm::dvec3(offsets[i], offsets[j], offsets[k])).x;
        if (t > 0.0 && t < 1.0) ts.push_back(t);
      }
    }
  }
  std::sort(ts.begin(), ts.end());
  ts.erase(std::unique(ts.begin(), ts.end()), ts.end());
  return ts;
}

bool outsideBox(glm::dvec3 x) {
  // sum_i t_i xi_i - c has |.|_inf <= sum |xi| / 2 = 2: K vanishes beyond.
  return std::max({std::abs(x.x), std::abs(x.y), std::abs(x.z)}) >= 2.0;
}

}  // namespace

double slowKernel(glm::dvec3 x) {
  if (outsideBox(x)) return 0.0;
  const glm::dvec3 z = x + kCentre;
  const std::vector<double> ts = breakpoints(z);
  auto s = [&](double t) { return section(z - t * kA[0], 0); };
  double integral = 0.0;
  for (std::size_t i = 0; i + 1 < ts.size(); ++i) {
    const double a = ts[i], b = ts[i + 1];
    integral += (b - a) / 6.0 * (s(a) + 4.0 * s(0.5 * (a + b)) + s(b));  // exact: S is quadratic
  }
  return integral;  // K = 2 M_Xi = 2 * integral of M_{Xi\a1} = integral of S
}

glm::dvec3 slowKernelGradient(glm::dvec3 x) {
  if (outsideBox(x)) return glm::dvec3(0.0);
  const glm::dvec3 z = x + kCentre;
  glm::dvec3 directional;  // a_k . grad K = 2 (M(z) - M(z - a_k)) = S(z) - S(z - a_k)
  for (int k = 0; k < 3; ++k) {
    directional[k] = section(z, k) - section(z - kA[static_cast<std::size_t>(k)], k);
  }
  const glm::dmat3 rows = glm::transpose(glm::dmat3(kA[0], kA[1], kA[2]));
  return glm::inverse(rows) * directional;
}

namespace {
template <class Term, class T>
T sumOverLattice(glm::dvec3 u, const std::function<double(glm::ivec3)>& c, Term term, T zero) {
  const glm::ivec3 o(glm::floor(u));
  T acc = zero;
  for (int k = o.z - 2; k <= o.z + 3; ++k) {
    for (int j = o.y - 2; j <= o.y + 3; ++j) {
      for (int i = o.x - 2; i <= o.x + 3; ++i) {
        if ((i + j + k) & 1) continue;
        const glm::ivec3 p(i, j, k);
        acc += c(p) * term(u - glm::dvec3(p));
      }
    }
  }
  return acc;
}
}  // namespace

double slowSpline(glm::dvec3 u, const std::function<double(glm::ivec3)>& c) {
  return sumOverLattice(u, c, slowKernel, 0.0);
}

glm::dvec3 slowSplineGradient(glm::dvec3 u, const std::function<double(glm::ivec3)>& c) {
  return sumOverLattice(u, c, slowKernelGradient, glm::dvec3(0.0));
}

}  // namespace tessera::lattice::test
