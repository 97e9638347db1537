#include <gtest/gtest.h>

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "tessera/core/Camera.h"

using namespace tessera;

namespace {
void expectNear(glm::dvec3 a, glm::dvec3 b, double eps = 1e-9) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}
}  // namespace

TEST(Camera, DefaultViewLooksFromPlusYWithZUp) {
  Camera c;
  c.frame({2.0, 2.0, 2.0});
  EXPECT_NEAR(c.radius, std::sqrt(3.0), 1e-12);
  const glm::dmat3 b = c.basis();
  expectNear(b[0], {-1, 0, 0});
  expectNear(b[1], {0, 0, 1});
  expectNear(b[2], {0, 1, 0});
  expectNear(c.eye(), {0, c.distance(), 0});
}

TEST(Camera, BasisIsOrthonormalAndRightHandedForAnyAngles) {
  Camera c;
  for (double az : {-170.0, -45.0, 0.0, 33.0, 90.0, 200.0}) {
    for (double el : {-90.0, -60.0, 0.0, 45.0, 89.0, 90.0}) {
      c.azimuthDeg = az;
      c.elevationDeg = el;
      const glm::dmat3 b = c.basis();
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(glm::length(b[i]), 1.0, 1e-12);
      EXPECT_NEAR(glm::dot(b[0], b[1]), 0.0, 1e-12);
      EXPECT_NEAR(glm::dot(b[0], b[2]), 0.0, 1e-12);
      expectNear(glm::cross(b[0], b[1]), b[2], 1e-12);
    }
  }
}

TEST(Camera, AzimuthNinetyLooksFromPlusX) {
  Camera c;
  c.azimuthDeg = 90;
  expectNear(c.basis()[2], {1, 0, 0});
  c.azimuthDeg = 0;
  c.elevationDeg = 90;
  expectNear(c.basis()[2], {0, 0, 1});  // from above
}

TEST(Camera, FramedSphereTouchesTheViewAtZoomOne) {
  Camera c;
  c.frame({10.0, 20.0, 30.0});
  c.fovYDeg = 40;
  // The ray through the top edge of the view is tangent to the sphere:
  // its distance to the target equals the radius.
  const Ray r = c.ndcRay(0.0, 1.0, 1.0);
  const glm::dvec3 toTarget = c.target - r.origin;
  const double along = glm::dot(toTarget, r.direction);
  const double dist = glm::length(toTarget - along * r.direction);
  EXPECT_NEAR(dist, c.radius, 1e-9);
  c.zoom = 2.0;
  EXPECT_NEAR(c.distance(), c.radius / std::sin(glm::radians(20.0)) / 2.0, 1e-9);
}

TEST(Camera, PixelRaysGoThroughPixelCentresTopRowFirst) {
  Camera c;
  c.frame({2, 2, 2});
  const Ray centre = c.pixelRay(1, 1, 3, 3);  // middle pixel of 3x3
  expectNear(centre.direction, -c.basis()[2]);
  const Ray top = c.pixelRay(1, 0, 3, 3);
  EXPECT_GT(glm::dot(top.direction, c.basis()[1]), 0.0);  // row 0 is above the centre
  const Ray right = c.pixelRay(2, 1, 3, 3);
  EXPECT_GT(glm::dot(right.direction, c.basis()[0]), 0.0);
}

TEST(Camera, OrthographicRaysAreParallelAndSpanTheFramedSphere) {
  Camera c;
  c.projection = Projection::Orthographic;
  c.frame({4, 4, 4});
  const Ray a = c.ndcRay(-1, -1, 1.0);
  const Ray b = c.ndcRay(1, 1, 1.0);
  expectNear(a.direction, b.direction);
  EXPECT_NEAR(glm::length(b.origin - a.origin), 2.0 * std::sqrt(2.0) * c.radius, 1e-9);
}

TEST(Camera, PanMovesTargetInViewPlane) {
  Camera c;
  c.frame({2, 2, 2});
  c.pan(0.5, 0.0);
  EXPECT_NEAR(glm::dot(c.target, c.basis()[2]), 0.0, 1e-12);
  EXPECT_GT(glm::dot(c.target, c.basis()[0]), 0.0);
}

// Radiological convention seen from the face: the patient's right is on the
// screen's left; from the patient's right side, anterior is on the right.
TEST(Camera, EdgeLabelsFollowThePatientFrame) {
  tessera::Camera cam;
  tessera::EdgeLabels l = tessera::edgeLabels(cam);
  EXPECT_EQ(l.left, "R");
  EXPECT_EQ(l.right, "L");
  EXPECT_EQ(l.top, "S");
  EXPECT_EQ(l.bottom, "I");
  cam.azimuthDeg = 90.0;
  l = tessera::edgeLabels(cam);
  EXPECT_EQ(l.left, "P");
  EXPECT_EQ(l.right, "A");
  cam.azimuthDeg = 180.0;
  cam.elevationDeg = 90.0;  // from above
  l = tessera::edgeLabels(cam);
  EXPECT_EQ(l.left, "L");
  EXPECT_EQ(l.right, "R");
  EXPECT_EQ(l.top, "A");  // looking down on the head, the nose is at the top
  cam.azimuthDeg = 40.0;
  cam.elevationDeg = 0.0;
  EXPECT_EQ(tessera::edgeLabels(cam).right, "LA");
}

// The camera's angles live in the patient frame; a mirrored storage turns
// the model-frame basis, not the view of the anatomy.
TEST(Camera, FrameOfAMirroredVolumeMirrorsTheModelBasisOnly) {
  tessera::Volume v = tessera::Volume::shapeOnly({10, 12, 14}, tessera::ScalarType::U8);
  v.setDirection(glm::dmat3(glm::dvec3(-1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 1)));
  tessera::Camera cam;
  cam.azimuthDeg = 30.0;
  cam.frame(v);
  const glm::dmat3 world = cam.worldBasis();
  const glm::dmat3 model = cam.basis();
  for (int c = 0; c < 3; ++c) {
    EXPECT_DOUBLE_EQ(model[c].x, -world[c].x);
    EXPECT_DOUBLE_EQ(model[c].y, world[c].y);
    EXPECT_DOUBLE_EQ(model[c].z, world[c].z);
  }
}
