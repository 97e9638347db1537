#include "tessera/layout/LayoutProbe.h"

#include <algorithm>

#include "gpu/gl.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/Program.h"

namespace tessera::layout {

std::vector<glm::vec3> LayoutProbe::voxelCentres(glm::ivec3 d) {
  std::vector<glm::vec3> out;
  out.reserve(static_cast<std::size_t>(d.x) * d.y * d.z);
  for (int z = 0; z < d.z; ++z) {
    for (int y = 0; y < d.y; ++y) {
      for (int x = 0; x < d.x; ++x) {
        out.emplace_back((x + 0.5f) / d.x, (y + 0.5f) / d.y, (z + 0.5f) / d.z);
      }
    }
  }
  return out;
}

std::vector<float> LayoutProbe::sample(const Layout& layout,
                                       const std::vector<glm::vec3>& positions) {
  if (!context_.caps().has("GL_EXT_color_buffer_float")) {
    throw GpuError("LayoutProbe needs GL_EXT_color_buffer_float");
  }
  if (positions.empty()) return {};
  const gpu::ApiLevel api = context_.caps().api;
  const gpu::Program program = gpu::Program::build(
      "probe(" + layout.name() + ")",
      {gpu::shaderPreamble(api, false, {}), gpu::embeddedShaderPart("render/fullscreen.vert.glsl")},
      {gpu::shaderPreamble(api, true, {}), layout.glsl(),
       gpu::embeddedShaderPart("layout/probe.frag.glsl")});

  // Lay the positions out in rows of at most 1024.
  const int width = static_cast<int>(std::min<std::size_t>(positions.size(), 1024));
  const int height = static_cast<int>((positions.size() + width - 1) / width);
  std::vector<float> packed(static_cast<std::size_t>(width) * height * 3, 0.0f);
  for (std::size_t i = 0; i < positions.size(); ++i) {
    packed[i * 3 + 0] = positions[i].x;
    packed[i * 3 + 1] = positions[i].y;
    packed[i * 3 + 2] = positions[i].z;
  }
  gpu::Texture posTex = gpu::Texture::create2D(context_.ledger(), "probe positions", GL_RGBA32F,
                                               width, height, GL_RGBA, GL_FLOAT, nullptr);
  {
    std::vector<float> rgba(static_cast<std::size_t>(width) * height * 4, 0.0f);
    for (std::size_t i = 0; i < packed.size() / 3; ++i) {
      for (int c = 0; c < 3; ++c) rgba[i * 4 + c] = packed[i * 3 + c];
    }
    posTex.update2D(GL_RGBA, GL_FLOAT, rgba.data());
  }
  posTex.setFilter(GL_NEAREST, GL_NEAREST);
  gpu::Framebuffer target =
      gpu::Framebuffer::create(context_.ledger(), "probe target", width, height, GL_RGBA32F);

  const gpu::FullscreenTriangle triangle(context_.ledger());
  target.bind();
  program.use();
  const int unit = layout.bind(program, 0);
  posTex.bind(unit);
  program.set("u_positions", unit);
  glDisable(GL_BLEND);
  triangle.draw();

  std::vector<float> rgba(static_cast<std::size_t>(width) * height * 4);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, rgba.data());
  const GLenum err = glGetError();
  if (err != GL_NO_ERROR) throw GpuError("LayoutProbe: GL error " + std::to_string(err));
  std::vector<float> out(positions.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = rgba[i * 4];
  return out;
}

}  // namespace tessera::layout
