#include "tessera/core/PatientFrame.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/matrix.hpp>

namespace tessera {

namespace {
constexpr double kDegPerRad = 180.0 / glm::pi<double>();

// Positive and negative letters of world axis a in RAS+.
char letter(int axis, bool positive) {
  static constexpr std::array<std::array<char, 2>, 3> kLetters{
      {{'R', 'L'}, {'A', 'P'}, {'S', 'I'}}};
  return kLetters[static_cast<std::size_t>(axis)][positive ? 0 : 1];
}

double angleDeg(const glm::dvec3& a, const glm::dvec3& b) {
  const double c = glm::dot(glm::normalize(a), glm::normalize(b));
  return std::acos(std::clamp(c, -1.0, 1.0)) * kDegPerRad;
}
}  // namespace

glm::dmat3 lpsToRas() {
  return glm::dmat3(glm::dvec3(-1.0, 0.0, 0.0), glm::dvec3(0.0, -1.0, 0.0),
                    glm::dvec3(0.0, 0.0, 1.0));
}

Orientation orientationOf(const glm::dmat3& direction) {
  // Try all 6 assignments of world axes to index axes and keep the one with
  // the largest total |cosine| (nibabel's io_orientation does the same
  // greedy-free choice), so that an oblique frame never gets a code with a
  // repeated axis such as "RRS".
  std::array<int, 3> perm{0, 1, 2}, best = perm;
  double bestScore = -1.0;
  do {
    double score = 0.0;
    for (int a = 0; a < 3; ++a) score += std::abs(direction[a][perm[static_cast<std::size_t>(a)]]);
    if (score > bestScore) {
      bestScore = score;
      best = perm;
    }
  } while (std::next_permutation(perm.begin(), perm.end()));

  Orientation o;
  for (int a = 0; a < 3; ++a) {
    const int w = best[static_cast<std::size_t>(a)];
    const glm::dvec3 col = direction[a];
    const bool positive = col[w] >= 0.0;
    o.code += letter(w, positive);
    glm::dvec3 axis(0.0);
    axis[w] = positive ? 1.0 : -1.0;
    o.maxObliqueDeg = std::max(o.maxObliqueDeg, angleDeg(col, axis));
  }
  for (int a = 0; a < 3; ++a) {
    for (int b = a + 1; b < 3; ++b) {
      o.shearDeg = std::max(o.shearDeg, std::abs(90.0 - angleDeg(direction[a], direction[b])));
    }
  }
  o.oblique = o.maxObliqueDeg > 1e-3;
  return o;
}

std::string Orientation::describe() const {
  if (!oblique && shearDeg <= 1e-3) return code;
  char buf[160];
  if (shearDeg > 1e-3) {
    std::snprintf(buf, sizeof buf, "oblique (nearest %s, %.3g deg off; axes sheared %.3g deg)",
                  code.c_str(), maxObliqueDeg, shearDeg);
  } else {
    std::snprintf(buf, sizeof buf, "oblique (nearest %s, %.3g deg off)", code.c_str(),
                  maxObliqueDeg);
  }
  return buf;
}

glm::dmat3 nearestOrthonormal(const glm::dmat3& direction) {
  // Newton iteration for the orthogonal polar factor: Q <- (Q + Q^-T) / 2.
  // Converges quadratically from any non-singular matrix and keeps the sign
  // of the determinant (a reflection stays a reflection).
  glm::dmat3 q = direction;
  for (int i = 0; i < 50; ++i) {
    const glm::dmat3 next = 0.5 * (q + glm::transpose(glm::inverse(q)));
    double change = 0.0;
    for (int c = 0; c < 3; ++c) change = std::max(change, glm::length(next[c] - q[c]));
    q = next;
    if (change < 1e-15) break;
  }
  return q;
}

char directionLetter(const glm::dvec3& d) {
  int axis = 0;
  for (int a = 1; a < 3; ++a) {
    if (std::abs(d[a]) > std::abs(d[axis])) axis = a;
  }
  return letter(axis, d[axis] >= 0.0);
}

std::string directionLabel(const glm::dvec3& d) {
  std::array<int, 3> order{0, 1, 2};
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return std::abs(d[a]) > std::abs(d[b]); });
  const double len = glm::length(d);
  std::string label;
  for (std::size_t i = 0; i < 3; ++i) {
    const int a = order[i];
    // sin(22.5 deg): an axis counts once the direction leans that far to it.
    if (i == 0 || std::abs(d[a]) > 0.38 * len) label += letter(a, d[a] >= 0.0);
  }
  return label;
}

}  // namespace tessera
