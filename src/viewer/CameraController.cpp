#include "tessera/viewer/CameraController.h"

#include <algorithm>
#include <cmath>
#include <iterator>

#include <glm/geometric.hpp>

namespace tessera::viewer {

void CameraController::setViewport(int width, int height) {
  viewport_ = glm::dvec2(std::max(width, 1), std::max(height, 1));
}

void CameraController::pointerDown(int id, glm::dvec2 pos, PointerAction action) {
  pointers_[id] = {pos, action};
}

void CameraController::pointerUp(int id) {
  pointers_.erase(id);
}

void CameraController::pointerMove(int id, glm::dvec2 pos) {
  auto it = pointers_.find(id);
  if (it == pointers_.end()) return;  // a hover, not a drag
  if (pointers_.size() == 1) {
    const glm::dvec2 d = pos - it->second.pos;
    it->second.pos = pos;
    if (it->second.action == PointerAction::Orbit) {
      // Dragging right turns the object right: the eye moves left.
      camera_->azimuthDeg -= d.x * kDegreesPerPixel;
      camera_->elevationDeg = std::clamp(camera_->elevationDeg + d.y * kDegreesPerPixel,
                                         -kMaxElevationDeg, kMaxElevationDeg);
      camera_->azimuthDeg = std::remainder(camera_->azimuthDeg, 360.0);
    } else {
      // Grab-and-move: the content follows the pointer.
      camera_->pan(-d.x / viewport_.y, d.y / viewport_.y);
    }
    return;
  }
  // Two (or more) pointers: the first two pinch and pan; others are ignored.
  auto a = pointers_.begin();
  auto b = std::next(a);
  if (it != a && it != b) return;
  const glm::dvec2 oldA = a->second.pos, oldB = b->second.pos;
  it->second.pos = pos;
  const glm::dvec2 newA = a->second.pos, newB = b->second.pos;
  const double oldDist = glm::length(oldB - oldA), newDist = glm::length(newB - newA);
  if (oldDist > 1.0 && newDist > 1.0) {
    camera_->zoom = std::clamp(camera_->zoom * newDist / oldDist, 0.05, 50.0);
  }
  const glm::dvec2 d = 0.5 * (newA + newB) - 0.5 * (oldA + oldB);
  camera_->pan(-d.x / viewport_.y, d.y / viewport_.y);
}

void CameraController::wheel(double notches) {
  camera_->zoom = std::clamp(camera_->zoom * std::pow(1.1, -notches), 0.05, 50.0);
}

}  // namespace tessera::viewer
