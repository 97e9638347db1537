#include "tessera/render/CameraRay.h"

#include <cmath>

#include <glm/gtc/constants.hpp>
#include <glm/vec2.hpp>

namespace tessera::render {

void setCameraRayUniforms(const gpu::Program& program, const Camera& camera, double aspect,
                          int width, int height, glm::dvec3 extent) {
  const glm::dmat3 b = camera.basis();
  program.set("u_eye", glm::vec3(camera.eye()));
  program.set("u_right", glm::vec3(b[0]));
  program.set("u_up", glm::vec3(b[1]));
  program.set("u_forward", glm::vec3(-b[2]));
  program.set("u_tanHalfFov",
              static_cast<float>(std::tan(0.5 * camera.fovYDeg * glm::pi<double>() / 180.0)));
  program.set("u_orthoHalfHeight", static_cast<float>(camera.orthoHalfHeight()));
  program.set("u_aspect", static_cast<float>(aspect));
  program.set("u_ortho", camera.projection == Projection::Orthographic ? 1 : 0);
  program.set("u_viewport", glm::vec2(width, height));
  program.set("u_extent", glm::vec3(extent));
}

}  // namespace tessera::render
