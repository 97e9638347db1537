#include "tessera/layout/LayoutProbe.h"

#include <algorithm>
#include <cstdint>

#include "tessera/core/Error.h"
#include "tessera/gpu/Draw.h"
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

bool LayoutProbe::hasFloatTargets() const {
  return context_.caps().api == gpu::ApiLevel::Gles3 &&
         context_.caps().has("GL_EXT_color_buffer_float");
}

std::vector<float> LayoutProbe::sample(const Layout& layout,
                                       const std::vector<glm::vec3>& positions) {
  if (positions.empty()) return {};
  if (!hasFloatTargets()) return sampleRgba8(layout, positions);
  const std::vector<glm::vec4> probed = probeFloat(layout, positions, false);
  std::vector<float> out(probed.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = probed[i].x;
  return out;
}

std::vector<glm::vec4> LayoutProbe::sampleGradient(const Layout& layout,
                                                   const std::vector<glm::vec3>& positions) {
  if (!hasFloatTargets()) {
    throw GpuError(
        "LayoutProbe: gradients need float render targets (ES 3 + "
        "EXT_color_buffer_float)");
  }
  if (positions.empty()) return {};
  return probeFloat(layout, positions, true);
}

// ES 3 with float render targets: positions in an RGBA32F texture read with
// texelFetch, values (or gradient and value) written to an RGBA32F target.
std::vector<glm::vec4> LayoutProbe::probeFloat(const Layout& layout,
                                               const std::vector<glm::vec3>& positions,
                                               bool gradient) {
  const gpu::ApiLevel api = context_.caps().api;
  std::vector<gpu::ShaderPart> fragment = {
      gpu::shaderPreamble(api, true,
                          gradient ? std::vector<std::string>{"TESSERA_PROBE_GRADIENT 1"}
                                   : std::vector<std::string>{})};
  for (gpu::ShaderPart& part : layout.seamParts()) fragment.push_back(std::move(part));
  fragment.push_back(gpu::embeddedShaderPart("layout/probe.frag.glsl"));
  const gpu::Program program = gpu::Program::build(
      "probe(" + layout.name() + (gradient ? ", gradient)" : ")"),
      {gpu::shaderPreamble(api, false, {}), gpu::embeddedShaderPart("render/fullscreen.vert.glsl")},
      fragment);

  // Lay the positions out in rows of at most 1024.
  const int width = static_cast<int>(std::min<std::size_t>(positions.size(), 1024));
  const int height = static_cast<int>((positions.size() + width - 1) / width);
  std::vector<float> packed(static_cast<std::size_t>(width) * height * 3, 0.0f);
  for (std::size_t i = 0; i < positions.size(); ++i) {
    packed[i * 3 + 0] = positions[i].x;
    packed[i * 3 + 1] = positions[i].y;
    packed[i * 3 + 2] = positions[i].z;
  }
  gpu::Texture posTex = gpu::Texture::create2D(context_.ledger(), "probe positions",
                                               gpu::TexelFormat::RGBA32F, width, height);
  {
    std::vector<float> rgba(static_cast<std::size_t>(width) * height * 4, 0.0f);
    for (std::size_t i = 0; i < packed.size() / 3; ++i) {
      for (int c = 0; c < 3; ++c) rgba[i * 4 + c] = packed[i * 3 + c];
    }
    posTex.update(rgba.data());
  }
  posTex.setFilter(gpu::Filter::Nearest);
  gpu::Framebuffer target = gpu::Framebuffer::create(context_.ledger(), "probe target", width,
                                                     height, gpu::TexelFormat::RGBA32F);

  const gpu::FullscreenTriangle triangle(context_.ledger());
  target.bind();
  program.use();
  const int unit = layout.bindSeam(program, 0);
  posTex.bind(unit);
  program.set("u_positions", unit);
  gpu::apply({});
  triangle.draw();

  std::vector<float> rgba(static_cast<std::size_t>(width) * height * 4);
  gpu::readPixelsRgba32F({0, 0, width, height}, rgba.data());
  std::vector<glm::vec4> out(positions.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = glm::vec4(rgba[i * 4], rgba[i * 4 + 1], rgba[i * 4 + 2], rgba[i * 4 + 3]);
  }
  return out;
}

// ES 2 (no float render targets, no texelFetch, float textures optional):
// one point per position, the position a float vertex attribute (exact, and
// constant over the point's one fragment), the value in two 8-bit channels.
std::vector<float> LayoutProbe::sampleRgba8(const Layout& layout,
                                            const std::vector<glm::vec3>& positions) {
  const gpu::ApiLevel api = context_.caps().api;
  const gpu::Program program = gpu::Program::build(
      "probe(" + layout.name() + ", rgba8)",
      {gpu::shaderPreamble(api, false, {}), gpu::embeddedShaderPart("layout/probe.vert.glsl")},
      {gpu::shaderPreamble(api, true, {"TESSERA_PROBE_RGBA8 1"}), layout.glsl(),
       gpu::embeddedShaderPart("layout/probe.frag.glsl")});

  // Position i goes to pixel (i % width, i / width), rows of at most 1024.
  const int width = static_cast<int>(std::min<std::size_t>(positions.size(), 1024));
  const int height = static_cast<int>((positions.size() + width - 1) / width);
  constexpr int kFloats = 5;  // clip-space pixel centre (2), probe position (3)
  std::vector<float> vertices(positions.size() * kFloats);
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const auto px = static_cast<float>(i % static_cast<std::size_t>(width));
    const auto py = static_cast<float>(i / static_cast<std::size_t>(width));
    float* v = vertices.data() + i * kFloats;
    v[0] = (px + 0.5f) / static_cast<float>(width) * 2.0f - 1.0f;
    v[1] = (py + 0.5f) / static_cast<float>(height) * 2.0f - 1.0f;
    v[2] = positions[i].x;
    v[3] = positions[i].y;
    v[4] = positions[i].z;
  }
  const gpu::Buffer buffer = gpu::Buffer::create(
      context_.ledger(), "probe points", gpu::BufferKind::Vertices, vertices.size() * sizeof(float),
      vertices.data(), gpu::BufferUsage::Static);
  // ES 2.0 takes an unsized colour format.
  gpu::Framebuffer target = gpu::Framebuffer::create(context_.ledger(), "probe target", width,
                                                     height, gpu::rgba8For(api));

  target.bind();
  gpu::apply({});
  gpu::clearColor(glm::vec4(0.0f));
  program.use();
  layout.bind(program, 0);
  const int probeAttribute = program.attributeLocation("a_probe");
  if (probeAttribute < 0) throw GpuError("LayoutProbe: probe.vert.glsl lacks a_probe");
  gpu::drawArrays(gpu::Primitive::Points, buffer, {{0, 2, 0}, {probeAttribute, 3, 2}}, kFloats, 0,
                  static_cast<int>(positions.size()));

  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(width) * height * 4);
  target.readRgba8(rgba.data());
  gpu::checkErrors("LayoutProbe");
  std::vector<float> out(positions.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const std::uint8_t* px = rgba.data() + i * 4;
    if (px[3] != 255) {
      throw GpuError("LayoutProbe: no fragment for position " + std::to_string(i) +
                     " (points not rasterised where expected)");
    }
    out[i] = static_cast<float>((px[0] + px[1] / 255.0) / 255.0);
  }
  return out;
}

}  // namespace tessera::layout
