#pragma once
// Orbit camera around a target (the volume's centre by default). The world
// box of a volume is extent() centred at the origin; world +z is "up".
// azimuth 0 / elevation 0 looks from +y towards -y (the face of a RAS head).
#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

namespace tessera {

enum class Projection { Perspective, Orthographic };

struct Ray {
  glm::dvec3 origin;
  glm::dvec3 direction;  // unit length
};

class Camera {
 public:
  double azimuthDeg = 0.0;    // rotation about world z
  double elevationDeg = 0.0;  // rotation about the camera's right axis
  double zoom = 1.0;          // >1 moves closer / magnifies
  double fovYDeg = 30.0;      // perspective only
  Projection projection = Projection::Perspective;
  glm::dvec3 target{0.0};  // orbit centre (pan moves it)
  double radius = 1.0;     // radius of the sphere framed at zoom 1

  // Frames a box of the given extent (sets radius = half its diagonal).
  void frame(glm::dvec3 extent);

  // Camera basis: columns right, up, back (forward = -back).
  glm::dmat3 basis() const;
  glm::dvec3 eye() const;
  double distance() const;         // eye to target
  double orthoHalfHeight() const;  // orthographic half height of the view

  // Ray through the centre of pixel (px, py) of a width x height image,
  // py counted from the top row. Perspective rays start at the eye,
  // orthographic rays at the eye plane.
  Ray pixelRay(int px, int py, int width, int height) const;
  // Same for normalised device coordinates in [-1,1] (y up).
  Ray ndcRay(double ndcX, double ndcY, double aspect) const;

  // Moves the target in the view plane by a fraction of the view height.
  void pan(double dxFraction, double dyFraction);
};

}  // namespace tessera
