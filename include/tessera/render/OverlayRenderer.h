#pragma once
// Rasterises overlay lines at full resolution into a "line layer": the
// nearest line's colour per pixel, and its distance along the pixel's ray
// (the ray parameter t of the ray caster: from the eye for perspective, from
// the eye plane for orthographic views). The hybrid compositor decides from
// that distance whether a line lies in front of the volume or must be
// attenuated, and the CPU ground truth (reference/ReferenceOverlay.h)
// terminates each ray at it — both see exactly the same line pixels.
// The distance is packed into the RGB bytes of an RGBA8 target (24 bits of
// t / distanceScale), which every ES 2.0 device can render to.
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

  // Draws `lines` (depth-tested among themselves) into width x height colour
  // and distance targets; pixels without a line get colour (0,0,0,0).
  void draw(const std::vector<OverlayLine>& lines, const Camera& camera, int width, int height);

  const gpu::Texture& colorTexture() const { return color_.color(); }
  const gpu::Texture& distanceTexture() const { return distance_.color(); }
  // World length that a packed distance of 1 stands for.
  double distanceScale() const { return distanceScale_; }

  // Read-backs, top row first: colour (alpha 255 on line pixels), and the
  // distance per pixel (+infinity where there is no line).
  Image readColor() const;
  std::vector<float> readDistance() const;

 private:
  void allocate(int width, int height);
  void drawPass(const gpu::Program& program, const glm::mat4& mvp, const Camera& camera,
                std::size_t vertexCount);

  gpu::GlContext& context_;
  gpu::Framebuffer color_;
  gpu::Framebuffer distance_;
  gpu::Buffer vertices_;
  gpu::Program colorProgram_;
  gpu::Program distanceProgram_;
  double distanceScale_ = 1.0;
};

}  // namespace tessera::render
