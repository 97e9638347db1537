#pragma once
// The uniforms of render/camera_ray.glsl — a camera's primary rays and the
// volume's box — for every full-screen pass that includes it: the hybrid
// compositor, and any technique that casts rays (tests/render/
// TechniqueRegistryTest.cpp's x-ray technique sets its rays with this).
#include <glm/vec3.hpp>

#include "tessera/core/Camera.h"
#include "tessera/gpu/Program.h"

namespace tessera::render {

// `program` must be in use. `aspect`: width / height of the screen the rays
// cover; width x height: the pixels of the target (gl_FragCoord's range);
// `extent`: the world size of the volume's box, centred at the origin.
void setCameraRayUniforms(const gpu::Program& program, const Camera& camera, double aspect,
                          int width, int height, glm::dvec3 extent);

}  // namespace tessera::render
