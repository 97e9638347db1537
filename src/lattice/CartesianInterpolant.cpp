#include "lattice/CartesianInterpolant.h"

#include <algorithm>
#include <cmath>

#include "lattice/ParallelFor.h"

namespace tessera::lattice::detail {

namespace {

// The pole of the cubic B-spline's interpolation filter (see below).
const double kPole = std::sqrt(3.0) - 2.0;
// Terms until kPole^j < 1e-16: the truncated sums are exact in double.
constexpr int kPoleTerms = 28;

// Runs cubicBSplinePrefilter along every line of `axis`.
void prefilterAxis(Volume& v, int axis, int threads) {
  const glm::ivec3 d = v.dims();
  const int u = (axis + 1) % 3, w = (axis + 2) % 3;
  float* data = v.dataAs<float>();
  const std::int64_t lines = static_cast<std::int64_t>(d[u]) * d[w];
  parallelFor(lines, threads, [&](std::int64_t begin, std::int64_t end) {
    std::vector<double> line(static_cast<std::size_t>(d[axis]));
    for (std::int64_t l = begin; l < end; ++l) {
      glm::ivec3 p(0);
      p[u] = static_cast<int>(l % d[u]);
      p[w] = static_cast<int>(l / d[u]);
      auto at = [&](int k) -> float& {
        p[axis] = k;
        return data[v.index(p.x, p.y, p.z)];
      };
      for (int k = 0; k < d[axis]; ++k) line[static_cast<std::size_t>(k)] = at(k);
      cubicBSplinePrefilter(line);
      for (int k = 0; k < d[axis]; ++k)
        at(k) = static_cast<float>(line[static_cast<std::size_t>(k)]);
    }
  });
}

}  // namespace

int mirrorIndex(int k, int n) {
  if (n == 1) return 0;
  const int period = 2 * n - 2;
  k %= period;
  if (k < 0) k += period;
  return k < n ? k : period - k;
}

// Interpolation asks for f_k = (c_{k-1} + 4 c_k + c_{k+1}) / 6 (the cubic
// B-spline is 1/6, 4/6, 1/6 at -1, 0, 1). With a = sqrt(3) - 2, the root of
// a^2 + 4a + 1 = 0 inside the unit circle, z + 4 + 1/z = -(1 - a/z)(1 - a z)/a,
// so c = -6a (1 - a/z)^-1 (1 - a z)^-1 f: a causal recursion y_k = f_k +
// a y_{k-1}, an anticausal one d_k = y_k + a d_{k+1}, and c_k = -6a d_k
// (Unser, Aldroubi & Eden 1993). The data are mirrored about both ends; each
// recursion starts from its infinite sum over the mirrored data.
void cubicBSplinePrefilter(std::vector<double>& f) {
  const int n = static_cast<int>(f.size());
  if (n < 2) return;  // a constant: its coefficients are its samples
  auto mirrored = [&](int k) { return f[static_cast<std::size_t>(mirrorIndex(k, n))]; };
  double y0 = 0.0, power = 1.0;
  for (int j = 0; j < kPoleTerms; ++j, power *= kPole) y0 += power * mirrored(-j);
  // Appended rather than assigned: GCC 12 with -fPIC otherwise warns of a
  // null dereference of an empty vector (n >= 2 here).
  std::vector<double> y;
  y.reserve(f.size());
  y.push_back(y0);
  for (int k = 1; k < n; ++k) y.push_back(f[static_cast<std::size_t>(k)] + kPole * y.back());
  // d_{n-1} = sum_j a^j y_{n-1+j}, continuing the causal recursion past the end.
  double dLast = 0.0, yk = y[static_cast<std::size_t>(n - 1)];
  power = 1.0;
  for (int j = 0; j < kPoleTerms; ++j, power *= kPole) {
    dLast += power * yk;
    yk = mirrored(n + j) + kPole * yk;
  }
  double d = dLast;
  f[static_cast<std::size_t>(n - 1)] = -6.0 * kPole * d;
  for (int k = n - 2; k >= 0; --k) {
    d = y[static_cast<std::size_t>(k)] + kPole * d;
    f[static_cast<std::size_t>(k)] = -6.0 * kPole * d;
  }
}

CartesianInterpolantField::CartesianInterpolantField(const Volume& source,
                                                     CartesianInterpolant kind, int threads)
    : kind_(kind), dims_(source.dims()) {
  data_ = Volume::allocate(dims_, ScalarType::F32, "f32 copy of the volume for FCC resampling");
  float* out = data_.dataAs<float>();
  const std::size_t n = static_cast<std::size_t>(source.voxelCount());
  for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<float>(source.finiteValueAtIndex(i));
  if (kind_ == CartesianInterpolant::CubicBSpline) {
    for (int axis = 0; axis < 3; ++axis) prefilterAxis(data_, axis, threads);
  }
}

std::array<double, 4> CartesianInterpolantField::weights(double t) const {
  const double t2 = t * t, t3 = t2 * t;
  switch (kind_) {
    case CartesianInterpolant::CubicBSpline:
      return {(1 - t) * (1 - t) * (1 - t) / 6.0, (4 - 6 * t2 + 3 * t3) / 6.0,
              (1 + 3 * t + 3 * t2 - 3 * t3) / 6.0, t3 / 6.0};
    case CartesianInterpolant::CatmullRom:
      // Keys (1981), "Cubic convolution interpolation", a = -1/2.
      return {(-t3 + 2 * t2 - t) / 2.0, (3 * t3 - 5 * t2 + 2) / 2.0, (-3 * t3 + 4 * t2 + t) / 2.0,
              (t3 - t2) / 2.0};
    case CartesianInterpolant::Trilinear:
      break;
  }
  return {0.0, 1.0 - t, t, 0.0};
}

double CartesianInterpolantField::at(glm::dvec3 x) const {
  std::array<std::array<double, 4>, 3> w;
  std::array<std::array<int, 4>, 3> tap;
  for (int a = 0; a < 3; ++a) {
    const double xa = std::clamp(x[a], 0.0, static_cast<double>(dims_[a] - 1));
    const int i = std::min(static_cast<int>(std::floor(xa)), std::max(dims_[a] - 2, 0));
    w[static_cast<std::size_t>(a)] = weights(xa - i);
    for (int k = 0; k < 4; ++k) {
      tap[static_cast<std::size_t>(a)][static_cast<std::size_t>(k)] =
          mirrorIndex(i - 1 + k, dims_[a]);
    }
  }
  const float* c = data_.dataAs<float>();
  double acc = 0.0;
  for (std::size_t kz = 0; kz < 4; ++kz) {
    if (w[2][kz] == 0.0) continue;
    for (std::size_t ky = 0; ky < 4; ++ky) {
      const double wyz = w[1][ky] * w[2][kz];
      if (wyz == 0.0) continue;
      const std::size_t row =
          (static_cast<std::size_t>(tap[2][kz]) * dims_.y + tap[1][ky]) * dims_.x;
      for (std::size_t kx = 0; kx < 4; ++kx) {
        acc += w[0][kx] * wyz * c[row + static_cast<std::size_t>(tap[0][kx])];
      }
    }
  }
  return acc;
}

}  // namespace tessera::lattice::detail
