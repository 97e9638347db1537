#pragma once
// The seam where rendering techniques plug into the viewer: a technique
// renders the volume into a colour texture of the requested size; the viewer
// presents that texture, draws the overlays and times the frame. "raycast"
// (render::Raycaster) is built in; other techniques (view-aligned and
// axis-aligned slicing, ...) register a factory under their name.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tessera/core/Camera.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/core/Volume.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/layout/Layout.h"

namespace tessera::viewer {

class ViewerTechnique {
 public:
  virtual ~ViewerTechnique() = default;
  virtual void setTransferFunction(const TransferFunction& tf) = 0;
  // Renders a width x height image and returns the GL name of a 2D colour
  // texture holding it (row 0 at the bottom, as GL stores it), valid until
  // the next call.
  virtual unsigned render(const Camera& camera, const RenderSettings& settings, int width,
                          int height) = 0;
};

// `volume` and `layout` outlive the technique.
using TechniqueFactory = std::function<std::unique_ptr<ViewerTechnique>(
    gpu::GlContext&, const Volume& volume, const layout::Layout& layout)>;

// Registers (or replaces) a technique under `name`.
void registerTechnique(const std::string& name, TechniqueFactory factory);
// Names of the registered techniques, "raycast" first.
std::vector<std::string> techniqueNames();
// InputError listing the names if `name` is unknown.
std::unique_ptr<ViewerTechnique> createTechnique(const std::string& name, gpu::GlContext& context,
                                                 const Volume& volume,
                                                 const layout::Layout& layout);

}  // namespace tessera::viewer
