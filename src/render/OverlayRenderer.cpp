#include "tessera/render/OverlayRenderer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include "render/FramebufferImage.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/Draw.h"
#include "tessera/render/CameraRay.h"

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
  colorProgram_ = gpu::Program::build(
      "overlay colour", vertex,
      {gpu::shaderPreamble(api, true, {}), gpu::embeddedShaderPart("render/camera_ray.glsl"),
       gpu::embeddedShaderPart("render/overlay_color.frag.glsl")});
  distanceProgram_ =
      gpu::Program::build("overlay distance", vertex,
                          {gpu::shaderPreamble(api, true, {}),
                           gpu::embeddedShaderPart("render/overlay_distance.frag.glsl")});
}

OverlayRenderer::~OverlayRenderer() = default;

void OverlayRenderer::allocate(int width, int height) {
  if (color_.id() != 0 && color_.width() == width && color_.height() == height) return;
  color_ = gpu::Framebuffer();
  // Each target has its depth buffer, cleared before its pass, so that where
  // lines cross the nearest one wins in colour and distance alike (the
  // distance target is made by readDistance, which needs it).
  color_ = gpu::Framebuffer::create(context_.ledger(), "overlay colour", width, height,
                                    gpu::rgba8For(context_.caps().api), true);
  // Sampled at pixel centres only: never blend two lines.
  color_.color().setFilter(gpu::Filter::Nearest);
}

double overlayFrontTolerance(const Camera& camera, int height, glm::dvec3 volumeExtent) {
  const double tanHalfFov = std::tan(0.5 * camera.fovYDeg * glm::pi<double>() / 180.0);
  const double viewHeight = camera.projection == Projection::Perspective
                                ? 2.0 * camera.distance() * tanHalfFov
                                : 2.0 * camera.orthoHalfHeight();
  return std::max(2.0 * viewHeight / height, 0.005 * glm::length(volumeExtent));
}

// The program's uniforms are set by the caller.
void OverlayRenderer::drawPass(const gpu::Program& program) {
  program.set("u_viewProjection", mvp_);
  gpu::clearColorAndDepth(glm::vec4(0.0f));
  if (vertexCount_ == 0) return;
  gpu::drawArrays(gpu::Primitive::Lines, vertices_,
                  {{program.attributeLocation("a_position"), 3, 0},
                   {program.attributeLocation("a_color"), 4, 3}},
                  7, 0, static_cast<int>(vertexCount_));
}

void OverlayRenderer::draw(const std::vector<OverlayLine>& lines, const Camera& camera, int width,
                           int height, glm::dvec3 volumeExtent) {
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
  const double aspect = static_cast<double>(width) / height;
  mvp_ = glm::mat4(viewProjection(camera, aspect, sceneRadius));
  camera_ = camera;
  vertexCount_ = data.size() / 7;

  gpu::apply({.depthTest = true, .lineWidth = 1.0f});
  color_.bind();
  colorProgram_.use();
  setCameraRayUniforms(colorProgram_, camera, aspect, width, height, volumeExtent);
  colorProgram_.set("u_frontTolerance",
                    static_cast<float>(overlayFrontTolerance(camera, height, volumeExtent)));
  drawPass(colorProgram_);
  gpu::apply({});
  gpu::checkErrors("overlay lines");
}

Image OverlayRenderer::readColor() const {
  return render::readImage(color_);
}

std::vector<float> OverlayRenderer::readDistance() {
  if (color_.id() == 0) throw InputError("overlay: no lines drawn yet to read distances of");
  if (distance_.id() == 0 || distance_.width() != color_.width() ||
      distance_.height() != color_.height()) {
    distance_ = gpu::Framebuffer();
    distance_ = gpu::Framebuffer::create(context_.ledger(), "overlay distance", color_.width(),
                                         color_.height(), gpu::rgba8For(context_.caps().api), true);
  }
  gpu::apply({.depthTest = true, .lineWidth = 1.0f});
  distance_.bind();
  distanceProgram_.use();
  const glm::dmat3 b = camera_.basis();
  distanceProgram_.set("u_eye", glm::vec3(camera_.eye()));
  distanceProgram_.set("u_forward", glm::vec3(-b[2]));
  distanceProgram_.set("u_ortho", camera_.projection == Projection::Orthographic ? 1 : 0);
  distanceProgram_.set("u_distanceScale", static_cast<float>(distanceScale_));
  drawPass(distanceProgram_);
  gpu::apply({});
  gpu::checkErrors("overlay distance");
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
