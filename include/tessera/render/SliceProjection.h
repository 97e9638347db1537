#pragma once
// The camera as matrices for the slicing techniques' proxy geometry, matching
// Camera::ndcRay (and so the ray caster and the CPU reference): world ->
// view is the camera basis at the eye; view -> clip is a perspective with
// the camera's vertical field of view, or orthographic with rays starting at
// the eye plane.
#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>

#include "tessera/core/Camera.h"

namespace tessera::render {

glm::dmat4 sliceWorldToView(const Camera& camera);
// `farPlane`: a distance from the eye beyond every slice.
glm::dmat4 sliceViewToClip(const Camera& camera, double aspect, double farPlane);

// The target a slicer renders for a requested width x height and a screen of
// aspect `viewAspect` (width / height; 0: the target's own): that size when
// it has the screen's shape, else the same pixel count in the screen's shape (128x128 for a
// 480x640 screen gives 111x148). The slicers have no view-aspect override —
// their projection always fills the target — so a compositor that stretches
// the target back gets the same fragment cost and no distortion.
glm::ivec2 sliceTargetSize(int width, int height, double viewAspect);

}  // namespace tessera::render
