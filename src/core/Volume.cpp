#include "tessera/core/Volume.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"

namespace tessera {

namespace {
template <class T>
ValueRange rangeOf(const T* p, std::size_t n) {
  if (n == 0) return {0.0, 0.0};
  T lo = p[0], hi = p[0];
  for (std::size_t i = 1; i < n; ++i) {
    lo = std::min(lo, p[i]);
    hi = std::max(hi, p[i]);
  }
  return {static_cast<double>(lo), static_cast<double>(hi)};
}

ValueRange rangeOfFloat(const float* p, std::size_t n) {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(p[i])) continue;  // NaN/Inf voxels do not define the range
    lo = std::min(lo, static_cast<double>(p[i]));
    hi = std::max(hi, static_cast<double>(p[i]));
  }
  if (lo > hi) return {0.0, 0.0};
  return {lo, hi};
}
}  // namespace

Volume Volume::allocate(glm::ivec3 dims, ScalarType type, const std::string& what) {
  constexpr std::int64_t kMaxDim = 1 << 20;
  for (int a = 0; a < 3; ++a) {
    if (dims[a] <= 0 || dims[a] > kMaxDim) {
      throw InputError(what + ": dimension " + std::to_string(a) + " is " +
                       std::to_string(dims[a]) + ", expected 1.." + std::to_string(kMaxDim));
    }
  }
  const std::uint64_t voxels = static_cast<std::uint64_t>(dims.x) *
                               static_cast<std::uint64_t>(dims.y) *
                               static_cast<std::uint64_t>(dims.z);
  const std::uint64_t bytes = voxels * bytesPerVoxel(type);
  HostBudget::global().check(bytes, what + " (" + std::to_string(dims.x) + "x" +
                                        std::to_string(dims.y) + "x" + std::to_string(dims.z) +
                                        " " + std::string(scalarTypeName(type)) + ")");
  Volume v;
  v.dims_ = dims;
  v.type_ = type;
  v.data_.assign(bytes);
  return v;
}

Volume Volume::borrow(glm::ivec3 dims, ScalarType type, std::span<std::byte> voxels,
                      std::shared_ptr<const void> lender, const std::string& what) {
  Volume v = shapeOnly(dims, type);
  v.rangeValid_ = false;
  const std::uint64_t expected = v.voxelCount() * bytesPerVoxel(type);
  if (dims.x <= 0 || dims.y <= 0 || dims.z <= 0 || voxels.size() != expected) {
    throw InputError(what + ": " + std::to_string(dims.x) + "x" + std::to_string(dims.y) + "x" +
                     std::to_string(dims.z) + " " + std::string(scalarTypeName(type)) + " needs " +
                     std::to_string(expected) + " bytes, the buffer has " +
                     std::to_string(voxels.size()));
  }
  if (!lender) throw InputError(what + ": borrowed voxels need an owner that keeps them alive");
  v.data_ = VoxelStorage(voxels, std::move(lender));
  return v;
}

Volume Volume::shapeOnly(glm::ivec3 dims, ScalarType type) {
  Volume v;
  v.dims_ = dims;
  v.type_ = type;
  v.range_ = {0.0, type == ScalarType::U8 ? 255.0 : 1.0};
  v.rangeValid_ = true;  // nothing to scan
  return v;
}

std::uint64_t Volume::voxelCount() const {
  return static_cast<std::uint64_t>(dims_.x) * static_cast<std::uint64_t>(dims_.y) *
         static_cast<std::uint64_t>(dims_.z);
}

void Volume::setSpacing(glm::dvec3 spacing) {
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(spacing[a]) || spacing[a] <= 0.0) {
      throw InputError("voxel spacing along axis " + std::to_string(a) + " is " +
                       std::to_string(spacing[a]) + ", expected a finite value > 0");
    }
  }
  spacing_ = spacing;
}

glm::dmat4 Volume::indexToWorld() const {
  glm::dmat4 m(1.0);
  for (int a = 0; a < 3; ++a) m[a] = glm::dvec4(direction_[a] * spacing_[a], 0.0);
  m[3] = glm::dvec4(origin_, 1.0);
  return m;
}

glm::dvec3 Volume::worldOf(glm::dvec3 index) const {
  return direction_ * (spacing_ * index) + origin_;
}

glm::dvec3 Volume::worldCentre() const {
  return worldOf(0.5 * (glm::dvec3(dims_) - 1.0));
}

void Volume::setIndexToWorld(const glm::dmat4& affine) {
  glm::dmat3 d;
  glm::dvec3 sp;
  for (int a = 0; a < 3; ++a) {
    d[a] = glm::dvec3(affine[a]);
    sp[a] = glm::length(d[a]);
  }
  const glm::dvec3 o(affine[3]);
  if (!std::isfinite(o.x) || !std::isfinite(o.y) || !std::isfinite(o.z)) {
    throw InputError("index-to-world affine has a non-finite origin");
  }
  setSpacing(sp);
  setDirection(d);
  origin_ = o;
}

void Volume::setDirection(const glm::dmat3& direction) {
  glm::dmat3 d;
  for (int a = 0; a < 3; ++a) {
    const double len = glm::length(direction[a]);
    if (!std::isfinite(len) || len <= 0.0) {
      throw InputError("direction of index axis " + std::to_string(a) +
                       " is zero or not finite; expected a unit vector");
    }
    d[a] = direction[a] / len;
  }
  // |det| of unit columns is the volume of their parallelepiped: near 0 means
  // two axes (almost) coincide and the voxels would collapse onto a plane.
  if (std::abs(glm::determinant(d)) < 1e-6) {
    throw InputError("index axes' directions are (nearly) parallel; the affine is singular");
  }
  direction_ = d;
}

double Volume::valueAtIndex(std::size_t i) const {
  switch (type_) {
    case ScalarType::U8:
      return dataAs<std::uint8_t>()[i];
    case ScalarType::U16:
      return dataAs<std::uint16_t>()[i];
    case ScalarType::I16:
      return dataAs<std::int16_t>()[i];
    case ScalarType::F32:
      return dataAs<float>()[i];
  }
  return 0.0;
}

namespace {
// Rounds to the nearest value of an integer voxel type, saturating. Clamping
// in double before rounding matters: std::lround of a value beyond `long`
// (1e30, +-Inf) or of NaN is unspecified (LONG_MIN on x86-64), which used to
// turn 1e30 into 0 instead of the type's maximum. NaN has no nearest integer
// and is stored as 0.
template <class T>
T roundToInteger(double v) {
  if (std::isnan(v)) return T{0};
  constexpr double lo = std::numeric_limits<T>::min();
  constexpr double hi = std::numeric_limits<T>::max();
  return static_cast<T>(std::lround(std::clamp(v, lo, hi)));
}
}  // namespace

void Volume::setValueAtIndex(std::size_t i, double v) {
  switch (type_) {
    case ScalarType::U8:
      dataAs<std::uint8_t>()[i] = roundToInteger<std::uint8_t>(v);
      break;
    case ScalarType::U16:
      dataAs<std::uint16_t>()[i] = roundToInteger<std::uint16_t>(v);
      break;
    case ScalarType::I16:
      dataAs<std::int16_t>()[i] = roundToInteger<std::int16_t>(v);
      break;
    case ScalarType::F32:
      dataAs<float>()[i] = static_cast<float>(v);
      break;
  }
  rangeValid_ = false;
}

double Volume::valueAt(int x, int y, int z) const {
  return valueAtIndex(index(x, y, z));
}

ValueRange Volume::valueRange() const {
  if (!rangeValid_) {
    const std::size_t n = static_cast<std::size_t>(voxelCount());
    switch (type_) {
      case ScalarType::U8:
        range_ = rangeOf(dataAs<std::uint8_t>(), n);
        break;
      case ScalarType::U16:
        range_ = rangeOf(dataAs<std::uint16_t>(), n);
        break;
      case ScalarType::I16:
        range_ = rangeOf(dataAs<std::int16_t>(), n);
        break;
      case ScalarType::F32:
        range_ = rangeOfFloat(dataAs<float>(), n);
        break;
    }
    rangeValid_ = true;
  }
  return range_;
}

std::uint64_t Volume::nonFiniteCount() const {
  if (type_ != ScalarType::F32 || !hasData()) return 0;
  const float* p = dataAs<float>();
  const std::size_t n = static_cast<std::size_t>(voxelCount());
  return static_cast<std::uint64_t>(
      std::count_if(p, p + n, [](float v) { return !std::isfinite(v); }));
}

double Volume::finiteValueAtIndex(std::size_t i) const {
  const double v = valueAtIndex(i);
  return std::isfinite(v) ? v : nonFiniteValue();
}

void Volume::setValueRange(ValueRange r) {
  if (!std::isfinite(r.min) || !std::isfinite(r.max) || r.max < r.min) {
    throw InputError("value range [" + std::to_string(r.min) + ", " + std::to_string(r.max) +
                     "] is reversed or not finite; expected min <= max");
  }
  range_ = r;
  rangeValid_ = true;
}

ValueRange Volume::window() const {
  if (hasWindow_) return window_;
  ValueRange r = valueRange();
  if (r.max <= r.min) r.max = r.min + 1.0;  // constant volume: avoid a zero-width window
  return r;
}

void Volume::setWindow(ValueRange w) {
  if (!std::isfinite(w.min) || !std::isfinite(w.max) || w.max <= w.min) {
    throw InputError("value window [" + std::to_string(w.min) + ", " + std::to_string(w.max) +
                     "] is empty or not finite; expected min < max");
  }
  window_ = w;
  hasWindow_ = true;
}

}  // namespace tessera
