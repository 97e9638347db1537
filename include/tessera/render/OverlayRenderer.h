#pragma once
// Rasterises overlay lines at full resolution into a "line layer": the
// nearest line's colour per pixel, with whether it lies in front of the
// volume box (decided per line fragment from its distance along the pixel's
// ray: the ray parameter t of the ray caster, from the eye for perspective,
// from the eye plane for orthographic views), which is all the hybrid
// compositor needs. The distance itself is drawn on request (readDistance):
// the CPU ground truth (reference/ReferenceOverlay.h) terminates each ray at
// it, so both see exactly the same line pixels. It is packed into the RGB
// bytes of an RGBA8 target (24 bits of t / distanceScale), which every
// ES 2.0 device can render to.
#include <vector>

#include <glm/mat4x4.hpp>

#include "tessera/core/Camera.h"
#include "tessera/core/Image.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/Program.h"
#include "tessera/render/Overlay.h"

namespace tessera::render {

// The projection that maps a world point to the pixel whose ray
// (Camera::pixelRay) passes through it; near/far enclose a sphere of
// `sceneRadius` around the camera target.
glm::dmat4 viewProjection(const Camera& camera, double aspect, double sceneRadius);

class OverlayRenderer {
 public:
  explicit OverlayRenderer(gpu::GlContext& context);
  ~OverlayRenderer();
  OverlayRenderer(const OverlayRenderer&) = delete;
  OverlayRenderer& operator=(const OverlayRenderer&) = delete;

  // Draws `lines` (depth-tested among themselves) into a width x height
  // colour target: RGB the nearest line's colour, alpha 1 where it lies in
  // front of the volume box (`volumeExtent`, world units, centred at the
  // origin) and 0.5 where it lies in or behind it; (0,0,0,0) without a line.
  void draw(const std::vector<OverlayLine>& lines, const Camera& camera, int width, int height,
            glm::dvec3 volumeExtent);

  const gpu::Texture& colorTexture() const { return color_.color(); }
  // World length that a packed distance of 1 stands for.
  double distanceScale() const { return distanceScale_; }

  // Read-backs of the last draw, top row first: colour (alpha 255 on line
  // pixels in front of the volume, 128 on the others, 0 elsewhere), and the
  // distance per pixel (+infinity where there is no line), whose pass is
  // drawn here.
  Image readColor() const;
  std::vector<float> readDistance();

 private:
  void allocate(int width, int height);
  void drawPass(const gpu::Program& program);

  gpu::GlContext& context_;
  gpu::Framebuffer color_;
  gpu::Framebuffer distance_;
  gpu::Buffer vertices_;
  gpu::Program colorProgram_;
  gpu::Program distanceProgram_;
  double distanceScale_ = 1.0;
  // The last draw's view, for its distance pass.
  Camera camera_;
  glm::mat4 mvp_{1.0f};
  std::size_t vertexCount_ = 0;
};

// How far behind the point where a pixel's ray enters the volume box a line
// still counts as in front of it (world units): the ray may meet the box up
// to a couple of pixels' footprint away from the line's point (a line on the
// box's front faces), and packing and float rounding.
double overlayFrontTolerance(const Camera& camera, int height, glm::dvec3 volumeExtent);

}  // namespace tessera::render
