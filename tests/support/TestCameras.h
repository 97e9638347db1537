#pragma once
// Cameras the image tests look through.
#include <glm/vec3.hpp>

#include "tessera/core/Camera.h"
#include "tessera/core/Volume.h"

namespace tessera::test {

// Orbiting the volume at (azimuth, elevation) degrees, oriented by its
// direction cosines (Camera::frame(volume)).
inline Camera orbitCamera(const Volume& v, double azimuthDeg, double elevationDeg) {
  Camera cam;
  cam.azimuthDeg = azimuthDeg;
  cam.elevationDeg = elevationDeg;
  cam.frame(v);
  return cam;
}

// The same around a box of this extent in the model frame (direction
// cosines left out: Camera::frame(extent)).
inline Camera orbitCamera(glm::dvec3 extent, double azimuthDeg, double elevationDeg) {
  Camera cam;
  cam.azimuthDeg = azimuthDeg;
  cam.elevationDeg = elevationDeg;
  cam.frame(extent);
  return cam;
}

// Looking along stack `axis` of a box of this extent: azimuth 90 looks along
// -x, azimuth 0 along -y, elevation 90 along -z.
inline Camera axisCamera(glm::dvec3 extent, int axis,
                         Projection projection = Projection::Perspective) {
  Camera cam = orbitCamera(extent, axis == 0 ? 90.0 : 0.0, axis == 2 ? 90.0 : 0.0);
  cam.projection = projection;
  return cam;
}

// Orthographic, looking down -z (slices of constant z face the viewer).
inline Camera topDownOrthographic(glm::dvec3 extent) {
  return axisCamera(extent, 2, Projection::Orthographic);
}

}  // namespace tessera::test
