#pragma once
// Putting data on the FCC lattice: resampling a Cartesian volume, sampling an
// analytic function directly, and the quasi-interpolation prefilter.
#include <cstdint>
#include <functional>
#include <optional>

#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"
#include "tessera/lattice/FccVolume.h"

namespace tessera::lattice {

// How a Cartesian volume is read between its voxel centres when the FCC
// points do not fall on them (`same` density; `half` reads the voxels
// themselves, so the interpolant plays no part).
//   CubicBSpline (default): cubic B-spline interpolation, i.e. the data are
//     first prefiltered into B-spline coefficients (Unser, Aldroubi & Eden,
//     "B-spline signal processing", IEEE TSP 1993; Thevenaz, Blu & Unser,
//     "Interpolation revisited", IEEE TMI 2000). Interpolating, C2, and of
//     approximation order 4, above the box spline's 3: resampling adds less
//     error than the box spline itself, so the lattice keeps its advantage.
//     Costs one f32 copy of the source (checked against HostBudget).
//   CatmullRom: Keys' cubic convolution (a = -1/2), interpolating, order 3.
//   Trilinear: order 2; its blur halves the high frequencies the box spline
//     could have kept (kept for comparison).
// All three read outside the volume by mirroring and clamp positions to the
// voxel-centre range, like the reference's clamp-to-edge.
enum class CartesianInterpolant { CubicBSpline, CatmullRom, Trilinear };

struct FccResampleOptions {
  FccDensity density = FccDensity::Same;
  CartesianInterpolant interpolant = CartesianInterpolant::CubicBSpline;
  // Apply quasiInterpolate() to the samples (see there): on by default, as
  // without it the box spline blurs away its advantage (at the same sample
  // count it then loses to Cartesian trilinear on Marschner-Lobb; with it it
  // wins by 1.4-2x, tests/lattice/MarschnerLobbQualityTest.cpp). Off: the
  // lattice holds point samples of the interpolated source.
  bool quasiInterpolate = true;
  // Texel type of the result; the source's when unset.
  std::optional<ScalarType> type;
  int threads = 0;  // 0: every hardware thread
};

struct FccResampleStats {
  // Values that did not fit an integer texel type and were saturated.
  std::uint64_t saturated = 0;
};

// The source's box and window on the FCC lattice of options.density. Memory:
// one f32 copy of the source (B-spline coefficients or samples; none at half
// density, which reads the voxels) plus two f32 copies of the lattice at
// most, all checked against HostBudget.
FccVolume resampleToFcc(const Volume& source, const FccResampleOptions& options = {},
                        FccResampleStats* stats = nullptr);

// f sampled at every lattice point over `box` (its dims define the density),
// f taking texture coordinates in [0,1]^3 of the box (called from several
// threads at once); quasi-interpolated unless asked not to. f32 texels.
FccVolume sampleOnFcc(const Volume& box, FccDensity density,
                      const std::function<double(glm::dvec3)>& f, bool quasiInterpolated = true,
                      int threads = 0);

// Coefficients that make the box spline reproduce quadratics exactly (so
// that its approximation order 3 is reached): c_j = f_j - laplacian(f)_j / 6,
// the Laplacian taken from the 12 nearest neighbours,
//   laplacian(f)_j = (1/4) sum_n (f_{j+n} - f_j),
// which is exact for quadratics. Why 1/6: the samples alone give q +
// laplacian(q) / 6 for a quadratic q, the box spline's second moment being
// I/3 per axis. Kim (Graphical Models 2013) quasi-interpolates FCC data
// before rendering for the same reason. f32 texels; neighbours outside the
// grid follow the boundary rule. InputError if `samples` already are.
FccVolume quasiInterpolate(const FccVolume& samples, int threads = 0);

}  // namespace tessera::lattice
