#include "tessera/render/OverlayRenderer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include "render/FramebufferImage.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/Draw.h"

namespace tessera::render {

glm::dmat4 viewProjection(const Camera& camera, double aspect, double sceneRadius) {
  const glm::dmat3 b = camera.basis();
  const glm::dvec3 eye = camera.eye();
  glm::dmat4 view(1.0);
  for (int c = 0; c < 3; ++c) {
    // Rows of the view matrix: right, up, back (column-major storage).
    view[c][0] = b[0][c];
    view[c][1] = b[1][c];
    view[c][2] = b[2][c];
  }
  view[3] = glm::dvec4(-glm::dot(b[0], eye), -glm::dot(b[1], eye), -glm::dot(b[2], eye), 1.0);
  const double d = glm::length(eye - camera.target);
  const double farZ = d + sceneRadius;
  glm::dmat4 proj(0.0);
  if (camera.projection == Projection::Perspective) {
    const double nearZ = std::max(d - sceneRadius, 1e-3 * farZ);
    const double f = 1.0 / std::tan(0.5 * camera.fovYDeg * glm::pi<double>() / 180.0);
    proj[0][0] = f / aspect;
    proj[1][1] = f;
    proj[2][2] = (farZ + nearZ) / (nearZ - farZ);
    proj[2][3] = -1.0;
    proj[3][2] = 2.0 * farZ * nearZ / (nearZ - farZ);
  } else {
    const double nearZ = d - sceneRadius;
    const double h = camera.orthoHalfHeight();
    proj[0][0] = 1.0 / (h * aspect);
    proj[1][1] = 1.0 / h;
    proj[2][2] = -2.0 / (farZ - nearZ);
    proj[3][2] = -(farZ + nearZ) / (farZ - nearZ);
    proj[3][3] = 1.0;
  }
  return proj * view;
}

OverlayRenderer::OverlayRenderer(gpu::GlContext& context) : context_(context) {
  const gpu::ApiLevel api = context.caps().api;
  const std::vector<gpu::ShaderPart> vertex{gpu::shaderPreamble(api, false, {}),
                                            gpu::embeddedShaderPart("render/overlay.vert.glsl")};
  colorProgram_ = gpu::Program::build("overlay colour", vertex,
                                      {gpu::shaderPreamble(api, true, {}),
                                       gpu::embeddedShaderPart("render/overlay_color.frag.glsl")});
  distanceProgram_ =
      gpu::Program::build("overlay distance", vertex,
                          {gpu::shaderPreamble(api, true, {}),
                           gpu::embeddedShaderPart("render/overlay_distance.frag.glsl")});
}

OverlayRenderer::~OverlayRenderer() = default;

void OverlayRenderer::allocate(int width, int height) {
  if (color_.id() != 0 && color_.width() == width && color_.height() == height) return;
  const gpu::TexelFormat format = gpu::rgba8For(context_.caps().api);
  color_ = gpu::Framebuffer();
  distance_ = gpu::Framebuffer();
  // Each target has its depth buffer, cleared before its pass, so that where
  // lines cross the nearest one wins in colour and distance alike.
  color_ =
      gpu::Framebuffer::create(context_.ledger(), "overlay colour", width, height, format, true);
  distance_ =
      gpu::Framebuffer::create(context_.ledger(), "overlay distance", width, height, format, true);
  // Sampled at pixel centres only: never blend two lines' packed distances.
  color_.color().setFilter(gpu::Filter::Nearest);
  distance_.color().setFilter(gpu::Filter::Nearest);
}

void OverlayRenderer::drawPass(const gpu::Program& program, const glm::mat4& mvp,
                               const Camera& camera, std::size_t vertexCount) {
  program.use();
  program.set("u_viewProjection", mvp);
  const glm::dmat3 b = camera.basis();
  program.set("u_eye", glm::vec3(camera.eye()));
  program.set("u_forward", glm::vec3(-b[2]));
  program.set("u_ortho", camera.projection == Projection::Orthographic ? 1 : 0);
  program.set("u_distanceScale", static_cast<float>(distanceScale_));
  gpu::clearColorAndDepth(glm::vec4(0.0f));
  if (vertexCount == 0) return;
  gpu::drawArrays(gpu::Primitive::Lines, vertices_,
                  {{program.attributeLocation("a_position"), 3, 0},
                   {program.attributeLocation("a_color"), 4, 3}},
                  7, 0, static_cast<int>(vertexCount));
}

void OverlayRenderer::draw(const std::vector<OverlayLine>& lines, const Camera& camera, int width,
                           int height) {
  if (width <= 0 || height <= 0) throw InputError("overlay: image size must be positive");
  allocate(width, height);
  std::vector<float> data;
  data.reserve(lines.size() * 14);
  double sceneRadius = camera.radius;
  for (const OverlayLine& l : lines) {
    for (const glm::dvec3& p : {l.a, l.b}) {
      sceneRadius = std::max(sceneRadius, glm::length(p - camera.target));
      data.insert(data.end(), {static_cast<float>(p.x), static_cast<float>(p.y),
                               static_cast<float>(p.z), l.color.r, l.color.g, l.color.b, 1.0f});
    }
  }
  sceneRadius *= 1.01;
  const double eyeDistance = glm::length(camera.eye() - camera.target);
  distanceScale_ = (eyeDistance + sceneRadius) * 1.001;
  if (!data.empty() && (vertices_.id() == 0 || vertices_.bytes() != data.size() * sizeof(float))) {
    vertices_ = gpu::Buffer();
    vertices_ =
        gpu::Buffer::create(context_.ledger(), "overlay lines", gpu::BufferKind::Vertices,
                            data.size() * sizeof(float), data.data(), gpu::BufferUsage::Dynamic);
  } else if (!data.empty()) {
    vertices_.update(0, data.size() * sizeof(float), data.data());
  }
  const glm::mat4 mvp(viewProjection(camera, static_cast<double>(width) / height, sceneRadius));

  gpu::apply({.depthTest = true, .lineWidth = 1.0f});
  color_.bind();
  drawPass(colorProgram_, mvp, camera, data.size() / 7);
  distance_.bind();
  drawPass(distanceProgram_, mvp, camera, data.size() / 7);
  gpu::apply({});
  gpu::checkErrors("overlay lines");
}

Image OverlayRenderer::readColor() const {
  return render::readImage(color_);
}

std::vector<float> OverlayRenderer::readDistance() const {
  const Image packed = render::readImage(distance_);
  std::vector<float> out(static_cast<std::size_t>(packed.width()) * packed.height(),
                         std::numeric_limits<float>::infinity());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const std::uint8_t* p = &packed.rgba()[i * 4];
    if (p[3] == 0) continue;
    const double v = p[0] * 65536.0 + p[1] * 256.0 + p[2];
    out[i] = static_cast<float>(v / 16777215.0 * distanceScale_);
  }
  return out;
}

}  // namespace tessera::render
