#pragma once
// The camera as matrices for the slicing techniques' proxy geometry, matching
// Camera::ndcRay (and so the ray caster and the CPU reference): world ->
// view is the camera basis at the eye; view -> clip is a perspective with
// the camera's vertical field of view, or orthographic with rays starting at
// the eye plane.
#include <glm/mat4x4.hpp>

#include "tessera/core/Camera.h"

namespace tessera::render {

glm::dmat4 sliceWorldToView(const Camera& camera);
// `farPlane`: a distance from the eye beyond every slice.
glm::dmat4 sliceViewToClip(const Camera& camera, double aspect, double farPlane);

}  // namespace tessera::render
