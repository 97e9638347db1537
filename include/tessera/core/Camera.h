#pragma once
// Orbit camera around a target (the volume's centre by default).
//
// Angles are in the patient frame (RAS+, core/PatientFrame.h): world +z
// (Superior) is "up", azimuth 0 / elevation 0 looks from +y (Anterior)
// towards -y, i.e. at the face, with the patient's right on the screen's
// left. Renderers work in a volume's model frame (extent() centred at the
// origin, axes along the index axes); `modelFromWorld` turns the camera
// into that frame, so basis(), eye() and the rays are model-frame
// quantities and every storage order of the same anatomy gives the same
// image. frame(volume) sets it from the volume's direction cosines.
#include <string>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"

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

  // World (patient) directions -> model-frame directions: the inverse of the
  // volume's (orthonormalised) direction matrix. Identity for RAS storage.
  glm::dmat3 modelFromWorld{1.0};

  // Frames a box of the given extent (sets radius = half its diagonal).
  void frame(glm::dvec3 extent);
  // Frames the volume and orients the camera by its direction cosines.
  void frame(const Volume& volume);
  // A camera at this azimuth and elevation that frames `volume` (frame()),
  // the other settings their defaults.
  static Camera framing(const Volume& volume, double azimuthDeg, double elevationDeg);

  // Camera basis in the model frame: columns right, up, back (forward =
  // -back). Orthonormal; left-handed when the volume's storage is mirrored.
  glm::dmat3 basis() const;
  // The same basis in the patient (world) frame: right, up, back in RAS.
  glm::dmat3 worldBasis() const;
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

// Patient directions at the edges of the screen, as radiology viewers label
// them ("R" on the left edge when looking at the face): each is the
// directionLabel() (core/PatientFrame.h) of the world direction that points
// to that edge, so oblique views get two or three letters ("LA").
struct EdgeLabels {
  std::string left, right, top, bottom;
};
EdgeLabels edgeLabels(const Camera& camera);

}  // namespace tessera
