#include "tessera/render/HybridSlice3DTechnique.h"

#include <algorithm>
#include <cmath>

#include "gpu/gl.h"

namespace tessera::render {

const gpu::Texture& HybridSlice3DTechnique::renderVolume(const Camera& camera,
                                                         const RenderSettings& settings, int width,
                                                         int height, double viewAspect) {
  int w = width, h = height;
  if (std::abs(static_cast<double>(width) / height - viewAspect) > 1e-3 * viewAspect) {
    const double pixels = static_cast<double>(width) * height;
    w = std::max(1, static_cast<int>(std::lround(std::sqrt(pixels * viewAspect))));
    h = std::max(1, static_cast<int>(std::lround(std::sqrt(pixels / viewAspect))));
  }
  Image img = slicer_.render(camera, settings, w, h);
  img.flipVertically();  // GL rows: bottom first
  const GLenum format = context_.caps().api == gpu::ApiLevel::Gles3 ? GL_RGBA8 : GL_RGBA;
  if (texture_.id() == 0 || texture_.width() != w || texture_.height() != h) {
    texture_ = gpu::Texture();
    texture_ = gpu::Texture::create2D(context_.ledger(), "slice3d hybrid upload", format, w, h,
                                      GL_RGBA, GL_UNSIGNED_BYTE, img.rgba().data());
  } else {
    texture_.update2D(GL_RGBA, GL_UNSIGNED_BYTE, img.rgba().data());
  }
  return texture_;
}

}  // namespace tessera::render
