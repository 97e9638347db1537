#include "tessera/core/Camera.h"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/matrix.hpp>

#include "tessera/core/PatientFrame.h"

namespace tessera {

namespace {
double radians(double deg) {
  return deg * glm::pi<double>() / 180.0;
}
}  // namespace

void Camera::frame(glm::dvec3 extent) {
  radius = 0.5 * glm::length(extent);
}

void Camera::frame(const Volume& volume) {
  frame(volume.extent());
  // The renderer's model box is axis-aligned, so a sheared (gantry-tilted)
  // frame is drawn with its nearest rotation; `info` reports the shear.
  modelFromWorld = glm::transpose(nearestOrthonormal(volume.direction()));
}

Camera Camera::framing(const Volume& volume, double azimuthDeg, double elevationDeg) {
  Camera cam;
  cam.azimuthDeg = azimuthDeg;
  cam.elevationDeg = elevationDeg;
  cam.frame(volume);
  return cam;
}

glm::dmat3 Camera::basis() const {
  return modelFromWorld * worldBasis();
}

glm::dmat3 Camera::worldBasis() const {
  // Start looking from +y towards the origin with +z up, then tilt by the
  // elevation about the right axis and turn by the azimuth about world z.
  // Building the basis by rotation keeps it well defined at the poles.
  const double az = radians(azimuthDeg);
  const double el = radians(elevationDeg);
  const double ca = std::cos(az), sa = std::sin(az);
  const double ce = std::cos(el), se = std::sin(el);
  // back = direction from target to eye.
  const glm::dvec3 back(sa * ce, ca * ce, se);
  // right is horizontal: at az = 0 the eye is on +y looking at -y, so the
  // screen's right is world -x.
  const glm::dvec3 right(-ca, sa, 0.0);
  const glm::dvec3 up = glm::cross(back, right);
  return glm::dmat3(right, up, back);
}

double Camera::distance() const {
  const double halfFov = 0.5 * radians(fovYDeg);
  return radius / std::sin(halfFov) / zoom;
}

double Camera::orthoHalfHeight() const {
  return radius / zoom;
}

glm::dvec3 Camera::eye() const {
  const double d = projection == Projection::Perspective ? distance() : 2.0 * radius + 1.0;
  return target + basis()[2] * d;
}

Ray Camera::ndcRay(double ndcX, double ndcY, double aspect) const {
  const glm::dmat3 b = basis();
  const glm::dvec3 forward = -b[2];
  if (projection == Projection::Perspective) {
    const double t = std::tan(0.5 * radians(fovYDeg));
    const glm::dvec3 dir = forward + b[0] * (ndcX * t * aspect) + b[1] * (ndcY * t);
    return {eye(), glm::normalize(dir)};
  }
  const double h = orthoHalfHeight();
  return {eye() + b[0] * (ndcX * h * aspect) + b[1] * (ndcY * h), forward};
}

Ray Camera::pixelRay(int px, int py, int width, int height) const {
  const double ndcX = (px + 0.5) / width * 2.0 - 1.0;
  const double ndcY = 1.0 - (py + 0.5) / height * 2.0;
  return ndcRay(ndcX, ndcY, static_cast<double>(width) / height);
}

void Camera::pan(double dxFraction, double dyFraction) {
  const glm::dmat3 b = basis();
  const double h = projection == Projection::Perspective
                       ? distance() * std::tan(0.5 * radians(fovYDeg))
                       : orthoHalfHeight();
  target += b[0] * (dxFraction * 2.0 * h) + b[1] * (dyFraction * 2.0 * h);
}

EdgeLabels edgeLabels(const Camera& camera) {
  const glm::dmat3 b = camera.worldBasis();
  return {directionLabel(-b[0]), directionLabel(b[0]), directionLabel(b[1]), directionLabel(-b[1])};
}

}  // namespace tessera
