#include "tessera/lattice/FccVolume.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include <glm/common.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"

namespace tessera::lattice {

namespace {

constexpr int kMaxGridDim = 1 << 20;

std::string dimsText(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

// The geometry and window of `source` without its voxels.
Volume boxOf(const Volume& source) {
  Volume box = Volume::shapeOnly(source.dims(), source.type());
  box.setIndexToWorld(source.indexToWorld());
  box.setGeometrySource(source.geometrySource());
  box.setWindow(source.window());
  box.setDescription(source.description());
  return box;
}

// Values an integer texel can hold; floats hold everything.
std::pair<double, double> representableRange(ScalarType type) {
  switch (type) {
    case ScalarType::U8:
      return {0.0, 255.0};
    case ScalarType::U16:
      return {0.0, 65535.0};
    case ScalarType::I16:
      return {-32768.0, 32767.0};
    case ScalarType::F32:
      break;
  }
  return {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
}

}  // namespace

FccDensity parseFccDensity(std::string_view text) {
  if (text == "same") return FccDensity::Same;
  if (text == "half") return FccDensity::Half;
  throw InputError("FCC density '" + std::string(text) +
                   "' is not one of: same (as many samples as the Cartesian volume), half");
}

std::string_view fccDensityName(FccDensity density) {
  return density == FccDensity::Same ? "same" : "half";
}

glm::ivec3 fccGridDims(glm::ivec3 cartesian, FccDensity density) {
  // One FCC point per 2 grid cells: cbrt(2) more grid planes per axis keep
  // the sample count.
  const double scale = density == FccDensity::Same ? std::cbrt(2.0) : 1.0;
  glm::ivec3 d;
  for (int a = 0; a < 3; ++a) {
    d[a] = std::max(2, static_cast<int>(std::lround(cartesian[a] * scale)));
  }
  return d;
}

FccVolume FccVolume::allocate(const Volume& box, glm::ivec3 gridDims, ScalarType type) {
  for (int a = 0; a < 3; ++a) {
    if (gridDims[a] < 2 || gridDims[a] > kMaxGridDim) {
      throw InputError("FCC grid " + dimsText(gridDims) + ": every dimension must be 2.." +
                       std::to_string(kMaxGridDim));
    }
  }
  FccVolume v;
  v.box_ = boxOf(box);
  v.grid_ = gridDims;
  v.packed_ = Volume::allocate(packedDims(gridDims), type, "FCC lattice " + dimsText(gridDims));
  v.packed_.setWindow(v.box_.window());
  return v;
}

FccVolume FccVolume::fromTexels(const Volume& box, glm::ivec3 gridDims, ScalarType type,
                                std::span<const float> texels, std::uint64_t* saturated) {
  FccVolume v = allocate(box, gridDims, type);
  const std::size_t n = static_cast<std::size_t>(v.packed_.voxelCount());
  if (texels.size() != n) {
    throw InputError("FCC lattice " + dimsText(gridDims) + ": " + std::to_string(texels.size()) +
                     " texels given, the packing has " + std::to_string(n));
  }
  const auto [lo, hi] = representableRange(type);
  std::uint64_t outside = 0;
  for (std::size_t i = 0; i < n; ++i) {
    glm::ivec3 p = v.pointAt(i);
    if (p.x >= gridDims.x) p.x -= 2;  // padding: the row's last point
    const double value = texels[v.index(p)];
    if (value < lo - 0.5 || value > hi + 0.5) ++outside;
    v.packed_.setValueAtIndex(i, value);
  }
  if (saturated) *saturated = outside;
  return v;
}

glm::ivec3 FccVolume::packedDims(glm::ivec3 gridDims) {
  return {(gridDims.x + 1) / 2, gridDims.y, gridDims.z};
}

std::uint64_t FccVolume::pointCount() const {
  const std::uint64_t cells = static_cast<std::uint64_t>(grid_.x) * grid_.y * grid_.z;
  // Only an all-odd grid has one more even point than odd ones.
  const bool allOdd = (grid_.x & grid_.y & grid_.z & 1) != 0;
  return (cells + (allOdd ? 1 : 0)) / 2;
}

glm::dvec3 FccVolume::gridSpacing() const {
  return box_.extent() / glm::dvec3(grid_);
}

glm::ivec3 FccVolume::pointAt(std::size_t index) const {
  const glm::ivec3 p = packed_.dims();
  const std::size_t row = index / static_cast<std::size_t>(p.x);
  const glm::ivec3 texel(static_cast<int>(index % static_cast<std::size_t>(p.x)),
                         static_cast<int>(row % static_cast<std::size_t>(p.y)),
                         static_cast<int>(row / static_cast<std::size_t>(p.y)));
  return pointOf(texel);
}

glm::ivec3 FccVolume::clampedTexel(glm::ivec3 point, glm::ivec3 gridDims) {
  return texelOf(glm::clamp(point, glm::ivec3(0), gridDims - 1));
}

double FccVolume::clampedValue(glm::ivec3 point) const {
  const glm::ivec3 t = clampedTexel(point, grid_);
  return packed_.valueAtIndex(packed_.index(t.x, t.y, t.z));
}

void FccVolume::setValue(glm::ivec3 point, double v) {
  packed_.setValueAtIndex(index(point), v);
  // An odd row of an odd-width grid ends one texel early; its padding
  // texel repeats the row's last point (the boundary rule reads it).
  if ((grid_.x & 1) && ((point.y + point.z) & 1) && point.x == grid_.x - 2) {
    packed_.setValueAtIndex(packed_.index(packed_.dims().x - 1, point.y, point.z), v);
  }
}

glm::dvec3 FccVolume::textureOf(glm::dvec3 gridCoord) const {
  return (gridCoord + 0.5) / glm::dvec3(grid_);
}

glm::dvec3 FccVolume::worldOf(glm::dvec3 gridCoord) const {
  return glm::dvec3(gridToWorld() * glm::dvec4(gridCoord, 1.0));
}

glm::dmat4 FccVolume::gridToWorld() const {
  // grid coordinate -> texture -> source index (centres at (i + 0.5) / N).
  const glm::dvec3 scale = glm::dvec3(box_.dims()) / glm::dvec3(grid_);
  glm::dmat4 toIndex(1.0);
  for (int a = 0; a < 3; ++a) {
    toIndex[a][a] = scale[a];
    toIndex[3][a] = 0.5 * scale[a] - 0.5;
  }
  return box_.indexToWorld() * toIndex;
}

std::string FccVolume::summary(std::string_view label) const {
  const glm::dvec3 h = gridSpacing();
  char spacing[96];
  std::snprintf(spacing, sizeof spacing, "%.4g x %.4g x %.4g", h.x, h.y, h.z);
  return std::string(label) + ": grid " + dimsText(grid_) + " (spacing " + spacing + "), " +
         std::to_string(pointCount()) + (quasiInterpolated_ ? " quasi-interpolated" : "") +
         " points, texels " + dimsText(packed_.dims()) + " " +
         std::string(scalarTypeName(packed_.type())) + " = " + formatBytes(byteSize());
}

}  // namespace tessera::lattice
