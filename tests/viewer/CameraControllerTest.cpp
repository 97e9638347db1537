#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "tessera/viewer/CameraController.h"

namespace tessera::viewer {
namespace {

Camera framedCamera() {
  Camera c;
  c.frame({100.0, 100.0, 100.0});
  return c;
}

TEST(CameraController, OneFingerDragOrbitsByDegreesPerPixel) {
  Camera c = framedCamera();
  CameraController ctl(c);
  ctl.setViewport(400, 400);
  ctl.pointerDown(1, {200, 200});
  ctl.pointerMove(1, {250, 180});
  EXPECT_NEAR(c.azimuthDeg, -50 * CameraController::kDegreesPerPixel, 1e-9);
  EXPECT_NEAR(c.elevationDeg, -20 * CameraController::kDegreesPerPixel, 1e-9);
  EXPECT_DOUBLE_EQ(c.zoom, 1.0);
  ctl.pointerUp(1);
  EXPECT_FALSE(ctl.interacting());
  ctl.pointerMove(1, {0, 0});  // hover after release: no change
  EXPECT_NEAR(c.azimuthDeg, -20.0, 1e-9);
}

TEST(CameraController, ElevationStaysBelowThePoles) {
  Camera c = framedCamera();
  CameraController ctl(c);
  ctl.pointerDown(1, {0, 0});
  ctl.pointerMove(1, {0, 5000});
  EXPECT_DOUBLE_EQ(c.elevationDeg, CameraController::kMaxElevationDeg);
}

TEST(CameraController, PinchZoomsByTheRatioOfFingerDistances) {
  Camera c = framedCamera();
  CameraController ctl(c);
  ctl.pointerDown(1, {100, 200});
  ctl.pointerDown(2, {300, 200});
  ctl.pointerMove(2, {500, 200});  // 200 px apart -> 400 px, midpoint moves too
  EXPECT_NEAR(c.zoom, 2.0, 1e-12);
  EXPECT_DOUBLE_EQ(c.azimuthDeg, 0.0);  // two fingers never orbit
}

TEST(CameraController, TwoFingersMovingTogetherPan) {
  Camera c = framedCamera();
  CameraController ctl(c);
  ctl.setViewport(400, 400);
  ctl.pointerDown(1, {100, 200});
  ctl.pointerDown(2, {300, 200});
  const glm::dvec3 before = c.target;
  ctl.pointerMove(1, {140, 200});
  ctl.pointerMove(2, {340, 200});
  EXPECT_GT(glm::length(c.target - before), 1.0);
  EXPECT_NEAR(c.zoom, 1.0, 1e-12);
}

TEST(CameraController, RightButtonPansAndWheelZooms) {
  Camera c = framedCamera();
  CameraController ctl(c);
  ctl.pointerDown(0, {10, 10}, PointerAction::Pan);
  ctl.pointerMove(0, {60, 10});
  EXPECT_GT(glm::length(c.target), 1.0);
  EXPECT_DOUBLE_EQ(c.azimuthDeg, 0.0);
  ctl.wheel(-1.0);  // towards the screen: zoom in
  EXPECT_NEAR(c.zoom, 1.1, 1e-12);
}

}  // namespace
}  // namespace tessera::viewer
