#include "tessera/viewer/ViewerTechnique.h"

#include <map>

#include "gpu/gl.h"
#include "tessera/core/Error.h"
#include "tessera/render/Raycaster.h"

namespace tessera::viewer {

namespace {

class RaycastTechnique : public ViewerTechnique {
 public:
  RaycastTechnique(gpu::GlContext& context, const Volume& volume, const layout::Layout& layout)
      : caster_(context, volume, layout) {}
  void setTransferFunction(const TransferFunction& tf) override { caster_.setTransferFunction(tf); }
  unsigned render(const Camera& camera, const RenderSettings& settings, int width,
                  int height) override {
    caster_.renderFrame(camera, settings, width, height);
    // renderFrame leaves its target framebuffer bound; its colour
    // attachment is the image (Raycaster keeps the target to itself).
    GLint type = 0, name = 0;
    glGetFramebufferAttachmentParameteriv(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0,
                                          GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &type);
    glGetFramebufferAttachmentParameteriv(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0,
                                          GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME, &name);
    if (type != GL_TEXTURE || name <= 0) {
      throw GpuError("ray caster left no colour texture bound (attachment type " +
                     std::to_string(type) + ")");
    }
    return static_cast<unsigned>(name);
  }

 private:
  render::Raycaster caster_;
};

std::map<std::string, TechniqueFactory>& registry() {
  static std::map<std::string, TechniqueFactory> r = {
      {"raycast", [](gpu::GlContext& c, const Volume& v, const layout::Layout& l) {
         return std::unique_ptr<ViewerTechnique>(new RaycastTechnique(c, v, l));
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
