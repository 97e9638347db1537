#pragma once
// The crop box (Clipping::cropMin/cropMax, fractions of each index axis) as
// something to grab in the 3D view: its 12 edges as overlay lines (composed
// by depth like the bounding box) and a handle at the centre of each face.
// Dragging a handle moves that face along its axis by the mouse motion
// projected onto the face normal's direction on the screen; the face stays
// inside the volume and at least kMinGap from the opposite face. Pure maths
// on the camera, shared by the desktop viewer and the web page.
#include <optional>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "tessera/core/Camera.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/render/Overlay.h"

namespace tessera::viewer {

// Face f of the box: axis f / 2, the minimum side when f is even.
constexpr int kCropFaces = 6;
inline int faceAxis(int face) {
  return face / 2;
}
inline bool faceIsMax(int face) {
  return face % 2 == 1;
}

// Pixel position (x right, y down, pixel centres at +0.5) of a model-frame
// point (the volume's box is extent centred at the origin), and the depth
// along the view direction; nullopt behind a perspective eye.
struct ScreenPoint {
  glm::dvec2 pixel;
  double depth;
};
std::optional<ScreenPoint> projectToScreen(const Camera& camera, glm::dvec3 model, int width,
                                           int height);

// The clip plane that follows the camera: perpendicular to the view
// direction, `depth` world units from the volume's centre towards the viewer
// (0: through the centre), keeping what lies beyond it; the kept part's cut
// face looks at the viewer from every camera angle. Patient frame, as
// Clipping::planes.
ClipPlane cameraFacingPlane(const Camera& camera, double depth);

class CropHandles {
 public:
  static constexpr double kMinGap = 0.02;  // fraction of the axis between opposite faces

  // Centre of face `face` of the crop box in the model frame.
  static glm::dvec3 faceCentre(const Clipping& clipping, glm::dvec3 extent, int face);

  // The box's 12 edges and a small cross at each face centre (the handle;
  // `active` drawn brighter), in the model frame.
  static std::vector<render::OverlayLine> lines(const Clipping& clipping, glm::dvec3 extent,
                                                std::optional<int> active = std::nullopt);

  // The face whose handle is nearest `pixel` within `radiusPx` (nearer the
  // viewer on a tie), or nullopt.
  static std::optional<int> hit(const Camera& camera, const Clipping& clipping, glm::dvec3 extent,
                                glm::dvec2 pixel, int width, int height, double radiusPx = 12.0);

  // Starts dragging `face` at `pixel`; move() then sets the face from the
  // total motion since begin(), so the face follows the mouse without drift.
  void begin(const Camera& camera, const Clipping& clipping, glm::dvec3 extent, int face,
             glm::dvec2 pixel, int width, int height);
  // Moves the face for the pointer at `pixel`; returns whether it changed.
  bool move(glm::dvec2 pixel, Clipping& clipping) const;
  void end() { face_.reset(); }
  std::optional<int> dragging() const { return face_; }

 private:
  std::optional<int> face_;
  glm::dvec2 start_{0.0};
  double startValue_ = 0.0;
  // Screen motion (pixels) per unit of the face's normalised coordinate.
  glm::dvec2 pixelsPerUnit_{0.0};
};

}  // namespace tessera::viewer
