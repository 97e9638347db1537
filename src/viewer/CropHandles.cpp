#include "tessera/viewer/CropHandles.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/trigonometric.hpp>

namespace tessera::viewer {

std::optional<ScreenPoint> projectToScreen(const Camera& camera, glm::dvec3 model, int width,
                                           int height) {
  // The inverse of Camera::ndcRay.
  const glm::dmat3 b = camera.basis();
  const glm::dvec3 v = model - camera.eye();
  const double depth = -glm::dot(v, b[2]);
  const double aspect = static_cast<double>(width) / height;
  double ndcX = 0.0, ndcY = 0.0;
  if (camera.projection == Projection::Perspective) {
    if (depth <= 1e-9) return std::nullopt;
    const double t = std::tan(0.5 * glm::radians(camera.fovYDeg));
    ndcX = glm::dot(v, b[0]) / (depth * t * aspect);
    ndcY = glm::dot(v, b[1]) / (depth * t);
  } else {
    const double h = camera.orthoHalfHeight();
    ndcX = glm::dot(v, b[0]) / (h * aspect);
    ndcY = glm::dot(v, b[1]) / h;
  }
  return ScreenPoint{{(ndcX + 1.0) * 0.5 * width, (1.0 - ndcY) * 0.5 * height}, depth};
}

ClipPlane cameraFacingPlane(const Camera& camera, double depth) {
  // The camera's back vector in the patient frame points at the viewer.
  return {camera.worldBasis()[2], depth};
}

glm::dvec3 CropHandles::faceCentre(const Clipping& clipping, glm::dvec3 extent, int face) {
  glm::dvec3 p = 0.5 * (clipping.cropMin + clipping.cropMax);
  const int a = faceAxis(face);
  p[a] = faceIsMax(face) ? clipping.cropMax[a] : clipping.cropMin[a];
  return (p - 0.5) * extent;
}

std::vector<render::OverlayLine> CropHandles::lines(const Clipping& clipping, glm::dvec3 extent,
                                                    std::optional<int> active) {
  std::vector<render::OverlayLine> out;
  const glm::vec4 edge(1.0f, 0.75f, 0.2f, 1.0f);  // orange: the crop box
  const glm::dvec3 lo = (clipping.cropMin - 0.5) * extent;
  const glm::dvec3 hi = (clipping.cropMax - 0.5) * extent;
  render::addBoxEdges(out, lo, hi, edge);
  // A cross in the face's plane, 6% of the box's smallest side.
  const double size = 0.06 * std::max(1e-9, std::min({extent.x, extent.y, extent.z}));
  for (int f = 0; f < kCropFaces; ++f) {
    const glm::vec4 color =
        active == f ? glm::vec4(1.0f, 1.0f, 0.4f, 1.0f) : glm::vec4(1.0f, 0.55f, 0.0f, 1.0f);
    const glm::dvec3 c = faceCentre(clipping, extent, f);
    const int a = faceAxis(f);
    for (int k = 1; k <= 2; ++k) {
      glm::dvec3 d(0.0);
      d[(a + k) % 3] = size;
      out.push_back({c - d, c + d, color});
    }
  }
  return out;
}

std::optional<int> CropHandles::hit(const Camera& camera, const Clipping& clipping,
                                    glm::dvec3 extent, glm::dvec2 pixel, int width, int height,
                                    double radiusPx) {
  std::optional<int> best;
  double bestDistance = 0.0, bestDepth = 0.0;
  for (int f = 0; f < kCropFaces; ++f) {
    const auto s = projectToScreen(camera, faceCentre(clipping, extent, f), width, height);
    if (!s) continue;
    const double d = glm::length(s->pixel - pixel);
    if (d > radiusPx) continue;
    // Handles within half a pixel of each other: the one nearer the viewer.
    const bool better =
        !best || d < bestDistance - 0.5 || (d < bestDistance + 0.5 && s->depth < bestDepth);
    if (better) {
      best = f;
      bestDistance = d;
      bestDepth = s->depth;
    }
  }
  return best;
}

void CropHandles::begin(const Camera& camera, const Clipping& clipping, glm::dvec3 extent, int face,
                        glm::dvec2 pixel, int width, int height) {
  face_ = face;
  start_ = pixel;
  const int a = faceAxis(face);
  startValue_ = faceIsMax(face) ? clipping.cropMax[a] : clipping.cropMin[a];
  // The screen motion of the face centre for a small step along its axis.
  const glm::dvec3 c = faceCentre(clipping, extent, face);
  constexpr double kProbe = 0.01;  // of the axis
  glm::dvec3 step(0.0);
  step[a] = kProbe * extent[a];
  const auto p0 = projectToScreen(camera, c, width, height);
  const auto p1 = projectToScreen(camera, c + step, width, height);
  pixelsPerUnit_ = p0 && p1 ? (p1->pixel - p0->pixel) / kProbe : glm::dvec2(0.0);
}

bool CropHandles::move(glm::dvec2 pixel, Clipping& clipping) const {
  if (!face_) return false;
  const double len2 = glm::dot(pixelsPerUnit_, pixelsPerUnit_);
  // An axis seen end-on (under a pixel per 1% of the axis) cannot be dragged.
  if (len2 < 1e4) return false;
  const int face = *face_;
  const int a = faceAxis(face);
  const double delta = glm::dot(pixel - start_, pixelsPerUnit_) / len2;
  double value = startValue_ + delta;
  if (faceIsMax(face)) {
    value = std::clamp(value, std::min(1.0, clipping.cropMin[a] + kMinGap), 1.0);
    if (value == clipping.cropMax[a]) return false;
    clipping.cropMax[a] = value;
  } else {
    value = std::clamp(value, 0.0, std::max(0.0, clipping.cropMax[a] - kMinGap));
    if (value == clipping.cropMin[a]) return false;
    clipping.cropMin[a] = value;
  }
  return true;
}

}  // namespace tessera::viewer
