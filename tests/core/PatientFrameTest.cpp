// Orientation codes and frames of core/PatientFrame.h, checked against the
// codes nibabel's aff2axcodes gives for the same matrices.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/core/Volume.h"

using namespace tessera;

namespace {
glm::dmat3 columns(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  return glm::dmat3(a, b, c);
}
glm::dmat3 rotationZ(double deg) {
  return glm::dmat3(glm::rotate(glm::dmat4(1.0), glm::radians(deg), glm::dvec3(0, 0, 1)));
}
}  // namespace

TEST(PatientFrame, AxisCodesNameWhereEachIndexAxisPoints) {
  EXPECT_EQ(orientationOf(glm::dmat3(1.0)).code, "RAS");
  EXPECT_EQ(orientationOf(lpsToRas()).code, "LPS");
  // DICOM sagittal (IOP 0\1\0\0\0\-1 in LPS): rows go posterior, columns inferior.
  const glm::dmat3 sagittalLps = columns({0, 1, 0}, {0, 0, -1}, {1, 0, 0});
  EXPECT_EQ(orientationOf(lpsToRas() * sagittalLps).code, "PIL");
  EXPECT_FALSE(orientationOf(lpsToRas() * sagittalLps).oblique);
}

TEST(PatientFrame, ObliqueFramesGetTheNearestCodeAndTheirAngle) {
  const Orientation o = orientationOf(rotationZ(20.0));
  EXPECT_EQ(o.code, "RAS");
  EXPECT_TRUE(o.oblique);
  EXPECT_NEAR(o.maxObliqueDeg, 20.0, 1e-9);
  EXPECT_NEAR(o.shearDeg, 0.0, 1e-9);
  EXPECT_NE(o.describe().find("oblique (nearest RAS, 20 deg off)"), std::string::npos);
  // 50 degrees: i is now closer to A than to R, and j to L; no repeated letter.
  EXPECT_EQ(orientationOf(rotationZ(50.0)).code, "ALS");
}

TEST(PatientFrame, NearestOrthonormalRemovesShearAndKeepsReflections) {
  glm::dmat3 sheared = lpsToRas();
  sheared[2] = glm::normalize(glm::dvec3(0.0, 0.2, 1.0));  // a gantry tilt of ~11 degrees
  EXPECT_GT(orientationOf(sheared).shearDeg, 10.0);
  const glm::dmat3 q = nearestOrthonormal(sheared);
  const glm::dmat3 qtq = glm::transpose(q) * q;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(qtq[c][r], r == c ? 1.0 : 0.0, 1e-12);
  }
  EXPECT_NEAR(glm::determinant(q), glm::determinant(sheared) > 0 ? 1.0 : -1.0, 1e-12);
  const glm::dmat3 rot = rotationZ(33.0) * lpsToRas();
  const glm::dmat3 same = nearestOrthonormal(rot);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(glm::length(same[c] - rot[c]), 0.0, 1e-12);
}

TEST(PatientFrame, VolumeAffineRoundTripsThroughItsParts) {
  Volume v = Volume::shapeOnly({5, 6, 7}, ScalarType::U8);
  glm::dmat4 a(0.0);
  a[0] = glm::dvec4(0.0, -0.9, 0.0, 0.0);
  a[1] = glm::dvec4(0.0, 0.0, -1.1, 0.0);
  a[2] = glm::dvec4(-2.0, 0.0, 0.0, 0.0);
  a[3] = glm::dvec4(10.0, 20.0, 30.0, 1.0);
  v.setIndexToWorld(a);
  EXPECT_EQ(orientationOf(v.direction()).code, "PIL");
  EXPECT_NEAR(v.spacing().x, 0.9, 1e-12);
  EXPECT_NEAR(v.spacing().z, 2.0, 1e-12);
  const glm::dmat4 back = v.indexToWorld();
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(glm::length(back[c] - a[c]), 0.0, 1e-12);
  const glm::dvec3 w = v.worldOf({1.0, 2.0, 3.0});
  EXPECT_NEAR(glm::length(w - glm::dvec3(10.0 - 6.0, 20.0 - 0.9, 30.0 - 2.2)), 0.0, 1e-12);
  EXPECT_THROW(
      v.setDirection(glm::dmat3(glm::dvec3(1, 0, 0), glm::dvec3(1, 0, 0), glm::dvec3(0, 0, 1))),
      InputError);
}

TEST(PatientFrame, DirectionLabelsNameLeaningAxes) {
  EXPECT_EQ(directionLabel({-1.0, 0.0, 0.0}), "L");
  EXPECT_EQ(directionLabel({-1.0, 1.0, 0.0}), "LA");
  EXPECT_EQ(directionLabel({0.1, -0.2, 1.0}), "S");
}
