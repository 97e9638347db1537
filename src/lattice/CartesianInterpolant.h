#pragma once
// A Cartesian volume read at any continuous voxel index, with one of the
// resampling interpolants of FccResampling.h.
#include <array>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"
#include "tessera/lattice/FccResampling.h"

namespace tessera::lattice::detail {

class CartesianInterpolantField {
 public:
  // Copies the source's finite values as f32 (prefiltered into B-spline
  // coefficients for CubicBSpline): BudgetError over HostBudget.
  CartesianInterpolantField(const Volume& source, CartesianInterpolant kind, int threads = 0);
  // Value at continuous voxel index x (centres at integers), x clamped to
  // [0, dims - 1] per axis.
  double at(glm::dvec3 x) const;

 private:
  // Weights of the taps floor(x) - 1 .. floor(x) + 2 along one axis.
  std::array<double, 4> weights(double t) const;

  CartesianInterpolant kind_;
  glm::ivec3 dims_;
  Volume data_;
};

// Index k of an axis of n samples under whole-sample mirroring.
int mirrorIndex(int k, int n);

// In-place cubic B-spline prefilter of one line of samples (mirror
// boundaries): afterwards sum_k c_k beta3(x - k) interpolates them.
void cubicBSplinePrefilter(std::vector<double>& line);

}  // namespace tessera::lattice::detail
