#pragma once
// The seam between the hybrid compositor and a volume technique (ray
// casting, view-aligned or axis-aligned slicing): the compositor asks for
// the volume alone, rendered into a target of its choosing, and does the
// upscaling, overlays and opacity estimation itself. A technique plugs in by
// implementing this one call (see HybridRaycastTechnique).
#include <string>

#include "tessera/core/Camera.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/gpu/GlObjects.h"

namespace tessera::render {

class HybridTechnique {
 public:
  virtual ~HybridTechnique() = default;
  virtual std::string name() const = 0;

  // Renders the volume, composited over settings.background, into a
  // width x height target whose pixels cover the view of a screen with
  // aspect ratio `viewAspect` (screen width / height; the target may have
  // another shape and is stretched when upscaled). Waits for the GPU and
  // returns the target's colour texture (row 0 at the bottom, linear
  // filtering), valid until the next call.
  virtual const gpu::Texture& renderVolume(const Camera& camera, const RenderSettings& settings,
                                           int width, int height, double viewAspect) = 0;
};

}  // namespace tessera::render
