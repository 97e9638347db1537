#include "tessera/render/SliceProjection.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat3x3.hpp>

namespace tessera::render {

glm::dmat4 sliceWorldToView(const Camera& camera) {
  const glm::dmat3 bt = glm::transpose(camera.basis());
  glm::dmat4 m(bt);
  m[3] = glm::dvec4(-(bt * camera.eye()), 1.0);
  return m;
}

glm::dmat4 sliceViewToClip(const Camera& camera, double aspect, double farPlane) {
  if (camera.projection == Projection::Perspective) {
    // Rays start at the eye; a near plane far closer than any voxel.
    return glm::perspective(camera.fovYDeg * glm::pi<double>() / 180.0, aspect, 1e-4 * farPlane,
                            farPlane);
  }
  const double h = camera.orthoHalfHeight();
  return glm::ortho(-h * aspect, h * aspect, -h, h, 0.0, farPlane);
}

glm::ivec2 sliceTargetSize(int width, int height, double viewAspect) {
  if (viewAspect <= 0.0 ||
      std::abs(static_cast<double>(width) / height - viewAspect) <= 1e-3 * viewAspect) {
    return {width, height};
  }
  const double pixels = static_cast<double>(width) * height;
  return {std::max(1, static_cast<int>(std::lround(std::sqrt(pixels * viewAspect)))),
          std::max(1, static_cast<int>(std::lround(std::sqrt(pixels / viewAspect))))};
}

}  // namespace tessera::render
