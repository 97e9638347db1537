#pragma once
// A volume sampled on the face-centred cubic (FCC) lattice
// {(i, j, k) in Z^3 : i + j + k even} over the box of a Cartesian volume.
//
// Geometry. The lattice lives in an enclosing Cartesian grid of gridDims() D
// spanning the source's box exactly: grid point u sits at texture position
// (u + 0.5) / D, the convention of every Cartesian layout, so the source's
// index -> world affine (box()) places FCC renders where the Cartesian
// original is. Grid spacing along each axis is extent / D.
//
// Density (Sarfaraz & Shaban 2015, Tables 1-2). The FCC lattice holds one
// point per 2 h^3 against one per d^3 for a Cartesian grid of spacing d:
//   same: D = round(N * cbrt(2)), spacing d / 1.26 (nearest neighbours
//         1.12 d apart); as many samples as the N-voxel source (to rounding).
//   half: D = N, spacing d: exactly the source's voxel centres with an even
//         index sum (no interpolation), half the samples.
// For an anisotropic source both are the FCC lattice of its index space (an
// affine image of FCC), which keeps `half` an exact subsampling.
//
// Storage: one texel per lattice point, packed along x. Row (j, k) holds the
// points i = 2m + ((j + k) & 1), m = 0 .. ceil(D.x / 2) - 1, so lattice point
// (i, j, k) is texel (i >> 1, j, k) and texel (m, j, k) is lattice point
// (2m + ((j + k) & 1), j, k). packed() is a Cartesian Volume of
// ceil(D.x/2) x D.y x D.z texels of the chosen scalar type: half the bytes of
// a full grid, the only waste being one texel per odd row when D.x is odd
// (it repeats the row's last point). Compared with Kim's four-channel
// packing of the 2Z^3 cosets (Graphical Models 2013) it costs one fetch per
// point instead of a quarter, but needs no channel select, wastes up to
// 1/D.x instead of up to 3/D of the texels, and keeps every fetch a plain
// integer address.
//
// Boundary rule (CPU and GPU alike): any integer point p the box spline asks
// for reads texel (clamp(p, 0, D - 1).x >> 1, clamp(p).y, clamp(p).z). Inside
// the grid that is p itself; outside it is a nearby point of the boundary
// rows, the FCC counterpart of clamp-to-edge.
//
// How a GLSL ES 3.00 shader fetches it: upload packed() as one
// single-channel 3D texture (R8 / R16 via R16UI or normalised R16F / R32F),
// NEAREST filtering, and read lattice point p (an ivec3) with
//   ivec3 c = clamp(p, ivec3(0), uGridDims - 1);
//   float v = texelFetch(uFcc, ivec3(c.x >> 1, c.y, c.z), 0).r;
// The lattice coordinate of texture position t is u = t * vec3(uGridDims) -
// 0.5; the 16 points of the box spline's stencil around u and their weights
// are in lattice/FccBoxSpline.h (same maths, CPU twin).
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"

namespace tessera::lattice {

enum class FccDensity { Same, Half };

// "same" or "half"; InputError naming the accepted values otherwise.
FccDensity parseFccDensity(std::string_view text);
std::string_view fccDensityName(FccDensity density);

// Enclosing grid of the FCC lattice over a Cartesian volume of `cartesian`
// dims at `density` (each axis at least 2).
glm::ivec3 fccGridDims(glm::ivec3 cartesian, FccDensity density);

class FccVolume {
 public:
  FccVolume() = default;

  // Zeroed lattice over `box`'s geometry (dims, spacing, origin, direction,
  // value window are copied; its voxels are not): InputError unless every
  // grid dim is 2..2^20, BudgetError over HostBudget.
  static FccVolume allocate(const Volume& box, glm::ivec3 gridDims, ScalarType type);

  // A lattice from texels computed elsewhere (packedDims(gridDims) of them,
  // in packed() order): integer types round to nearest and saturate, and
  // `saturated` (if given) counts the values that did not fit. Padding texels
  // are set from their row's last point whatever `texels` holds there.
  static FccVolume fromTexels(const Volume& box, glm::ivec3 gridDims, ScalarType type,
                              std::span<const float> texels, std::uint64_t* saturated = nullptr);

  // Texel dims of the packing of a grid: (ceil(D.x / 2), D.y, D.z).
  static glm::ivec3 packedDims(glm::ivec3 gridDims);
  static bool isLatticePoint(glm::ivec3 p) { return ((p.x + p.y + p.z) & 1) == 0; }
  // Lattice point -> its texel, and a texel -> the lattice point it holds
  // (outside the grid for a padding texel).
  static glm::ivec3 texelOf(glm::ivec3 point) { return {point.x >> 1, point.y, point.z}; }
  static glm::ivec3 pointOf(glm::ivec3 texel) {
    return {2 * texel.x + ((texel.y + texel.z) & 1), texel.y, texel.z};
  }

  // The texel the boundary rule reads for any integer point.
  static glm::ivec3 clampedTexel(glm::ivec3 point, glm::ivec3 gridDims);

  glm::ivec3 gridDims() const { return grid_; }
  // Lattice points inside the grid (padding excluded).
  std::uint64_t pointCount() const;
  // Bytes of packed(): what a texture of it costs.
  std::uint64_t byteSize() const { return packed_.byteSize(); }
  // World distance between grid planes along each index axis.
  glm::dvec3 gridSpacing() const;

  // Whether the texels are quasi-interpolation coefficients
  // (quasiInterpolate(), FccResampling.h) or point samples; either way the
  // box spline takes them as its coefficients.
  bool quasiInterpolated() const { return quasiInterpolated_; }
  void setQuasiInterpolated(bool q) { quasiInterpolated_ = q; }

  // The source's box: geometry and value window, no voxels. Pass it to
  // renderReference() with a BoxSplineReconstruction.
  const Volume& box() const { return box_; }
  // The texels (padding included); its dims are packedDims(gridDims()).
  const Volume& packed() const { return packed_; }

  // Linear index into packed() of an in-grid lattice point, and its inverse
  // (texel index -> the lattice point it holds).
  std::size_t index(glm::ivec3 point) const {
    return packed_.index(point.x >> 1, point.y, point.z);
  }
  glm::ivec3 pointAt(std::size_t index) const;

  // Value of an in-grid lattice point; value of any integer point under the
  // boundary rule.
  double value(glm::ivec3 point) const { return packed_.valueAtIndex(index(point)); }
  double clampedValue(glm::ivec3 point) const;
  // Writes an in-grid lattice point (and the padding texel that repeats it).
  void setValue(glm::ivec3 point, double v);

  // Texture position in [0,1]^3 of the box of a grid coordinate, and the
  // world position (via the source's index -> world affine).
  glm::dvec3 textureOf(glm::dvec3 gridCoord) const;
  glm::dvec3 worldOf(glm::dvec3 gridCoord) const;
  glm::dmat4 gridToWorld() const;

  // "FCC same density: grid 52x52x52 (spacing 0.0394), 70304 points, texels
  // 26x52x52 f32 = 275 KiB".
  std::string summary(std::string_view label) const;

 private:
  Volume box_;
  Volume packed_;
  glm::ivec3 grid_{0};
  bool quasiInterpolated_ = false;
};

}  // namespace tessera::lattice
