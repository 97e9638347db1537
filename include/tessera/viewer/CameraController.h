#pragma once
// Camera interaction shared by the desktop and web front ends: mouse drag
// orbits (right button or shift: pan), the wheel zooms; on touch screens one
// finger orbits, two fingers pinch to zoom and move together to pan
// (Schultz 2016, 7.5). Positions are in pixels, y down, as pointer events
// deliver them.
#include <map>

#include <glm/vec2.hpp>

#include "tessera/core/Camera.h"

namespace tessera::viewer {

enum class PointerAction { Orbit, Pan };

class CameraController {
 public:
  // Degrees of orbit per pixel of drag.
  static constexpr double kDegreesPerPixel = 0.4;
  // Elevation stays inside (-90, 90) so "up" never flips.
  static constexpr double kMaxElevationDeg = 89.0;

  explicit CameraController(Camera& camera) : camera_(&camera) {}
  void setCamera(Camera& camera) { camera_ = &camera; }

  void setViewport(int width, int height);

  // One pointer (mouse button or finger) per id; `action` is what a single
  // pointer does (a second finger always turns the gesture into pinch/pan).
  void pointerDown(int id, glm::dvec2 pos, PointerAction action = PointerAction::Orbit);
  void pointerMove(int id, glm::dvec2 pos);
  void pointerUp(int id);
  void cancel() { pointers_.clear(); }
  // Wheel notches (positive = towards the user = zoom out, as DOM deltaY).
  void wheel(double notches);

  bool interacting() const { return !pointers_.empty(); }
  int pointerCount() const { return static_cast<int>(pointers_.size()); }

 private:
  struct Pointer {
    glm::dvec2 pos;
    PointerAction action;
  };
  Camera* camera_;
  glm::dvec2 viewport_{512.0, 512.0};
  std::map<int, Pointer> pointers_;
};

}  // namespace tessera::viewer
