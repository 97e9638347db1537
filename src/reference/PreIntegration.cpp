#include "tessera/reference/PreIntegration.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/common.hpp>

#include "tessera/core/Error.h"

namespace tessera {

namespace {

// a0 is capped here so that tau stays finite: an opaque TF value gives a
// sample of length L an opacity of 1 - 1e-9^(L/unit), within 3e-5 of 1 for
// half a unit.
constexpr double kMaxOpacity = 1.0 - 1e-9;

}  // namespace

PreIntegral::PreIntegral(const TransferFunction& tf, double opacityScale, int cells)
    : tf_(tf), scale_(opacityScale), cells_(cells) {
  if (cells < 2)
    throw InputError("pre-integration: at least 2 cells, got " + std::to_string(cells));
  if (!std::isfinite(opacityScale) || opacityScale < 0.0) {
    throw InputError("pre-integration: opacity scale must be finite and >= 0");
  }
  if (!(tf.opacityUnitLength > 0.0)) {
    throw InputError("pre-integration: opacity unit length must be > 0");
  }
  t_.resize(static_cast<std::size_t>(cells) + 1);
  k_.resize(static_cast<std::size_t>(cells) + 1);
  // Running sums in double over 16k cells: the rounding error stays ~1e-12
  // of the total, far below what a half-float table holds.
  double prevTau = extinction(0.0);
  glm::dvec3 prevEmission = prevTau * tf_.color(0.0);
  t_[0] = 0.0;
  k_[0] = glm::dvec3(0.0);
  const double h = 1.0 / cells;
  for (int i = 1; i <= cells; ++i) {
    const double x = static_cast<double>(i) / cells;
    const double tau = extinction(x);
    const glm::dvec3 emission = tau * tf_.color(x);
    t_[static_cast<std::size_t>(i)] =
        t_[static_cast<std::size_t>(i) - 1] + 0.5 * h * (prevTau + tau);
    k_[static_cast<std::size_t>(i)] =
        k_[static_cast<std::size_t>(i) - 1] + 0.5 * h * (prevEmission + emission);
    prevTau = tau;
    prevEmission = emission;
  }
}

double PreIntegral::extinction(double x) const {
  const double a0 = std::clamp(tf_.opacity(std::clamp(x, 0.0, 1.0)) * scale_, 0.0, kMaxOpacity);
  return -std::log1p(-a0) / tf_.opacityUnitLength;
}

double PreIntegral::integralT(double x) const {
  const double u = std::clamp(x, 0.0, 1.0) * cells_;
  const int i = std::min(static_cast<int>(u), cells_ - 1);
  const double f = u - i;
  const auto a = static_cast<std::size_t>(i);
  return t_[a] + f * (t_[a + 1] - t_[a]);
}

glm::dvec3 PreIntegral::integralK(double x) const {
  const double u = std::clamp(x, 0.0, 1.0) * cells_;
  const int i = std::min(static_cast<int>(u), cells_ - 1);
  const double f = u - i;
  const auto a = static_cast<std::size_t>(i);
  return k_[a] + f * (k_[a + 1] - k_[a]);
}

glm::dvec4 PreIntegral::segment(double front, double back, double length) const {
  front = std::clamp(front, 0.0, 1.0);
  back = std::clamp(back, 0.0, 1.0);
  return fromIntegrals(front, back, integralT(front), integralT(back), integralK(front),
                       integralK(back), length);
}

glm::dvec4 PreIntegral::fromIntegrals(double front, double back, double tFront, double tBack,
                                      glm::dvec3 kFront, glm::dvec3 kBack, double length) const {
  const double d = back - front;
  const double mid = 0.5 * (front + back);
  // Within a millionth of the value range the segment is a sample: the
  // difference quotients would only add rounding noise.
  if (std::abs(d) < 1e-6) {
    const double tau = extinction(mid);
    return glm::dvec4(tf_.color(mid), -std::expm1(-tau * length));
  }
  const double dT = tBack - tFront;  // same sign as d
  const double alpha = -std::expm1(-dT / d * length);
  glm::dvec3 rgb = tf_.color(mid);  // transparent segments: any colour
  if (std::abs(dT) > 1e-12) rgb = (kBack - kFront) / dT;
  return glm::dvec4(glm::clamp(rgb, 0.0, 1.0), alpha);
}

std::vector<float> bakePreIntegrationTable(const PreIntegral& integral, int entries,
                                           double length) {
  if (entries < 2 || entries > 4096) {
    throw InputError("pre-integration table: 2..4096 entries per axis, got " +
                     std::to_string(entries));
  }
  if (!std::isfinite(length) || length < 0.0) {
    throw InputError("pre-integration table: segment length must be finite and >= 0");
  }
  // T and K at the N grid values once; then each entry is a difference of
  // two (the O(N^2) integral-table method), exactly segment(x_i, x_j).
  const auto n = static_cast<std::size_t>(entries);
  std::vector<double> x(n), t(n);
  std::vector<glm::dvec3> k(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = static_cast<double>(i) / (entries - 1);
    t[i] = integral.integralT(x[i]);
    k[i] = integral.integralK(x[i]);
  }
  std::vector<float> table(n * n * 4);
  for (std::size_t j = 0; j < n; ++j) {
    for (std::size_t i = 0; i < n; ++i) {
      const glm::dvec4 s = integral.fromIntegrals(x[i], x[j], t[i], t[j], k[i], k[j], length);
      float* e = &table[(j * n + i) * 4];
      for (int c = 0; c < 4; ++c) e[c] = static_cast<float>(s[c]);
    }
  }
  return table;
}

}  // namespace tessera
