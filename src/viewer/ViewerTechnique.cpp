#include "tessera/viewer/ViewerTechnique.h"

#include <map>
#include <memory>
#include <utility>

#include "tessera/core/Error.h"
#include "tessera/render/Raycaster.h"
#include "tessera/render/Slice2DRenderer.h"
#include "tessera/render/Slice3DRenderer.h"

namespace tessera::viewer {

namespace {

// Adapts any renderer with renderFrame() and colorTexture() (ray caster,
// view- and axis-aligned slicing) to the viewer's seam.
template <class Renderer>
class RendererTechnique : public ViewerTechnique {
 public:
  template <class... Args>
  explicit RendererTechnique(Args&&... args) : renderer_(std::forward<Args>(args)...) {}
  void setTransferFunction(const TransferFunction& tf) override {
    renderer_.setTransferFunction(tf);
  }
  unsigned render(const Camera& camera, const RenderSettings& settings, int width,
                  int height) override {
    renderer_.renderFrame(camera, settings, width, height);
    return renderer_.colorTexture().id();
  }

 private:
  Renderer renderer_;
};

std::map<std::string, TechniqueFactory>& registry() {
  static std::map<std::string, TechniqueFactory> r = {
      {"raycast",
       [](gpu::GlContext& c, const Volume& v, const layout::Layout& l) {
         return std::unique_ptr<ViewerTechnique>(
             std::make_unique<RendererTechnique<render::Raycaster>>(c, v, l));
       }},
      // View-aligned slicing samples through the layout like the ray caster.
      {"slice3d",
       [](gpu::GlContext& c, const Volume& v, const layout::Layout& l) {
         return std::unique_ptr<ViewerTechnique>(
             std::make_unique<RendererTechnique<render::Slice3DRenderer>>(c, v, l));
       }},
      // Axis-aligned slicing keeps its own atlases (post-classified, so a TF
      // edit costs only a table upload).
      {"slice2d", [](gpu::GlContext& c, const Volume& v, const layout::Layout&) {
         return std::unique_ptr<ViewerTechnique>(
             std::make_unique<RendererTechnique<render::Slice2DRenderer>>(
                 c, v, render::Slice2DOptions{}));
       }}};
  return r;
}

}  // namespace

void registerTechnique(const std::string& name, TechniqueFactory factory) {
  registry()[name] = std::move(factory);
}

std::vector<std::string> techniqueNames() {
  std::vector<std::string> names{"raycast"};
  for (const auto& [name, f] : registry())
    if (name != "raycast") names.push_back(name);
  return names;
}

std::unique_ptr<ViewerTechnique> createTechnique(const std::string& name, gpu::GlContext& context,
                                                 const Volume& volume,
                                                 const layout::Layout& layout) {
  auto it = registry().find(name);
  if (it == registry().end()) {
    std::string known;
    for (const auto& n : techniqueNames()) known += (known.empty() ? "" : ", ") + n;
    throw InputError("unknown technique '" + name + "' (available: " + known + ")");
  }
  return it->second(context, volume, layout);
}

}  // namespace tessera::viewer
