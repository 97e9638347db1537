#pragma once
// Volumes with non-trivial index -> world affines for the geometry tests,
// and an affine comparison that names the element that differs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <sstream>
#include <string>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>

#include "tessera/core/Volume.h"

namespace tessera::test {

// LAS storage (x flipped, as FSL/MNI atlases and nibabel's anatomical.nii):
// diag(-2, 1.5, 3) with an origin that is exact in float (NIfTI-1 stores
// the affine as float32).
inline glm::dmat4 lasAffine() {
  glm::dmat4 a(1.0);
  a[0][0] = -2.0;
  a[1][1] = 1.5;
  a[2][2] = 3.0;
  a[3] = glm::dvec4(90.5, -126.25, -72.0, 1.0);
  return a;
}

// An oblique acquisition: a rotation of 25 degrees about (1, 2, 3) and of
// 10 degrees about x, anisotropic spacing, float-exact origin.
inline glm::dmat4 obliqueAffine() {
  const glm::dmat4 r = glm::rotate(
      glm::rotate(glm::dmat4(1.0), glm::radians(25.0), glm::normalize(glm::dvec3(1, 2, 3))),
      glm::radians(10.0), glm::dvec3(1, 0, 0));
  glm::dmat4 a = r * glm::scale(glm::dmat4(1.0), glm::dvec3(0.75, 1.25, 2.5));
  a[3] = glm::dvec4(-40.5, 12.25, 30.125, 1.0);
  return a;
}

// The oblique frame with its first axis reversed (a left-handed frame:
// qfac -1 in NIfTI's qform).
inline glm::dmat4 obliqueReflectedAffine() {
  glm::dmat4 a = obliqueAffine();
  a[0] = -a[0];
  return a;
}

inline Volume volumeWithAffine(glm::ivec3 dims, ScalarType type, const glm::dmat4& affine,
                               unsigned seed = 7) {
  Volume v = Volume::allocate(dims, type, "geometry test");
  std::mt19937 rng(seed);
  for (std::size_t i = 0; i < v.voxelCount(); ++i) {
    v.setValueAtIndex(i, type == ScalarType::I16 ? static_cast<double>(rng() % 4000) - 2000.0
                                                 : static_cast<double>(rng() % 250));
  }
  v.invalidateRange();
  v.setIndexToWorld(affine);
  return v;
}

inline std::string affineText(const glm::dmat4& m) {
  std::ostringstream os;
  for (int r = 0; r < 3; ++r) {
    os << "[" << m[0][r] << " " << m[1][r] << " " << m[2][r] << " " << m[3][r] << "]";
  }
  return os.str();
}

inline void expectAffineNear(const glm::dmat4& actual, const glm::dmat4& expected, double tol) {
  double worst = 0.0;
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) worst = std::max(worst, std::abs(actual[c][r] - expected[c][r]));
  }
  EXPECT_LE(worst, tol) << "affine " << affineText(actual) << "\n expected "
                        << affineText(expected);
}

inline void expectSameVoxels(const Volume& a, const Volume& b) {
  ASSERT_EQ(a.dims(), b.dims());
  ASSERT_EQ(a.type(), b.type());
  ASSERT_EQ(a.byteSize(), b.byteSize());
  EXPECT_EQ(std::memcmp(a.bytes().data(), b.bytes().data(), a.byteSize()), 0)
      << "voxel bytes differ";
}

}  // namespace tessera::test
