#include "tessera/viewer/Viewer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/Histogram.h"
#include "tessera/core/HostBudget.h"
#include "tessera/core/Timing.h"
#include "tessera/gpu/DeviceSession.h"
#include "tessera/gpu/Draw.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/Program.h"
#include "tessera/lod/InCoreVolumeSource.h"

namespace tessera::viewer {

namespace {

constexpr int kHistogramBins = 256;
// Render-target size the plan reserves memory for (the largest frame we expect).
constexpr int kPlanImageSize = 1024;
constexpr int kSkipBlock = 8;

// The raster equivalent of Camera's rays (render/camera_ray.glsl), so that
// overlay lines land where the ray caster puts the volume.
glm::mat4 viewProjection(const Camera& camera, double aspect) {
  const glm::dmat3 b = camera.basis();
  const glm::dvec3 eye = camera.eye();
  const glm::dmat4 view = glm::lookAt(eye, eye - b[2], b[1]);
  const double dist = glm::length(eye - camera.target);
  const double farPlane = dist + 4.0 * camera.radius;
  glm::dmat4 proj;
  if (camera.projection == Projection::Perspective) {
    const double nearPlane = std::max(1e-3 * camera.radius, dist - 2.0 * camera.radius);
    proj = glm::perspective(glm::radians(camera.fovYDeg), aspect, nearPlane, farPlane);
  } else {
    const double h = camera.orthoHalfHeight();
    proj = glm::ortho(-h * aspect, h * aspect, -h, h, 1e-3, farPlane);
  }
  return glm::mat4(proj * view);
}

}  // namespace

struct Viewer::Gpu {
  gpu::Program present;
  gpu::Program lines;
  gpu::FullscreenTriangle triangle;
  gpu::Buffer lineVertices;
  int lineVertexCount = 0;
  glm::dvec3 lineExtent{-1.0};
};

Viewer::Viewer(gpu::GlContext& context, const gpu::DeviceProfile& profile)
    : context_(context),
      limits_(gpu::applyProfile(profile, context)),
      volume_(std::make_shared<Volume>()),
      gpu_(std::make_unique<Gpu>()) {
  const gpu::ApiLevel api = context.caps().api;
  gpu_->present = gpu::Program::build(
      "viewer present",
      {gpu::shaderPreamble(api, false, {}), gpu::embeddedShaderPart("viewer/present.vert.glsl")},
      {gpu::shaderPreamble(api, true, {}), gpu::embeddedShaderPart("viewer/present.frag.glsl")});
  gpu_->lines = gpu::Program::build(
      "viewer lines",
      {gpu::shaderPreamble(api, false, {}), gpu::embeddedShaderPart("viewer/lines.vert.glsl")},
      {gpu::shaderPreamble(api, true, {}), gpu::embeddedShaderPart("viewer/lines.frag.glsl")});
  gpu_->triangle = gpu::FullscreenTriangle(context_.ledger());
}

Viewer::~Viewer() {
  // GL objects go while the context is still current (the front end's job).
  active_ = {};
  gpu_.reset();
}

render::TechniqueOnVolume Viewer::createActive(const std::string& technique,
                                               const lod::VolumeSource& source) const {
  render::TechniqueOnVolume t = render::createTechnique(
      technique, context_, limits_, source,
      {.imageSize = {kPlanImageSize, kPlanImageSize}, .skipBlock = kSkipBlock});
  t.technique->setTransferFunction(tfEditor_.transferFunction());
  return t;
}

void Viewer::setVolume(Volume volume, const std::string& name) {
  if (!volume.hasData()) throw InputError(name + ": the volume has no voxels");
  const lod::InCoreVolumeSource source(std::make_shared<Volume>(std::move(volume)));
  render::TechniqueOnVolume next;
  try {
    next = createActive(techniqueName_, source);
  } catch (const BudgetError& e) {
    if (!hasVolume()) throw;
    throw BudgetError(name + ": does not fit the GPU budget next to the current volume (" +
                      formatBytes(context_.ledger().budget()) + "): " + e.what());
  }
  // Everything worked: swap in.
  active_ = std::move(next);
  volume_ = source.level(glm::ivec3(1));
  volumeName_ = name;
  uploadedTfRevision_ = tfEditor_.revision();
  updateHistogram();
  resetCamera();
}

EdgeLabels Viewer::orientationLabels() const {
  if (!volume_ || !volume_->hasData() || volume_->geometrySource().empty()) return {};
  return edgeLabels(camera_);
}

void Viewer::resetCamera() {
  camera_ = Camera{};
  if (volume_->hasData()) camera_.frame(*volume_);
}

void Viewer::setWindow(ValueRange w) {
  if (!volume_->hasData()) return;
  if (!(std::isfinite(w.min) && std::isfinite(w.max)) || !(w.max > w.min)) {
    throw InputError("window must have finite min < max");
  }
  volume_->setWindow(w);
  if (active_.upload.volume != volume_) active_.upload.volume->setWindow(w);
  updateHistogram();
}

void Viewer::resetWindow() {
  if (!volume_->hasData()) return;
  volume_->resetWindow();
  if (active_.upload.volume != volume_) active_.upload.volume->resetWindow();
  updateHistogram();
}

void Viewer::updateHistogram() {
  tfEditor_.setHistogram(Histogram::compute(*volume_, kHistogramBins, volume_->window()));
}

void Viewer::setTechnique(const std::string& name) {
  if (name == techniqueName_) return;
  render::TechniqueRegistry::global().find(name);  // InputError listing the names
  if (hasVolume()) {
    const lod::InCoreVolumeSource source(volume_);
    try {
      active_ = createActive(name, source);
    } catch (const BudgetError&) {
      // Both uploads do not fit the budget: the current one goes first, and
      // comes back if the new one does not fit alone either.
      active_ = {};
      try {
        active_ = createActive(name, source);
      } catch (const Error&) {
        active_ = createActive(techniqueName_, source);
        throw;
      }
    }
    uploadedTfRevision_ = tfEditor_.revision();
  }
  techniqueName_ = name;
}

std::string Viewer::storageName() const {
  return hasVolume() ? active_.storageName() : "";
}

std::string Viewer::description() const {
  if (!hasVolume()) return "no volume";
  std::ostringstream s;
  const glm::ivec3 d = volume_->dims();
  const layout::Plan& p = plan();
  s << volumeName_ << " " << d.x << "x" << d.y << "x" << d.z << " "
    << scalarTypeName(volume_->type()) << "; " << storageName() << " on "
    << gpu::apiLevelName(limits_.api);
  if (p.downsampled()) {
    const glm::ivec3 r = p.volumeDims;
    s << " (downsampled to " << r.x << "x" << r.y << "x" << r.z << ")";
  }
  return s.str();
}

// The volume through the technique at the quality level's size and step.
RenderSettings Viewer::frameSettings() const {
  RenderSettings settings = settings_;
  if (clipPlaneFollowsCamera &&
      settings.clipping.planes.size() < static_cast<std::size_t>(kMaxClipPlanes)) {
    // The camera's back vector in the patient frame: towards the viewer.
    settings.clipping.planes.push_back({camera_.worldBasis()[2], followingPlaneDistance});
  }
  return settings;
}

const gpu::Texture& Viewer::renderVolume(int width, int height, FrameStats& stats,
                                         render::QualityLevel& level) {
  if (uploadedTfRevision_ != tfEditor_.revision()) {
    active_.technique->setTransferFunction(tfEditor_.transferFunction());
    uploadedTfRevision_ = tfEditor_.revision();
  }
  RenderSettings settings = frameSettings();
  if (quality == Quality::Adaptive) {
    qualityController_.setInteracting(controller_.interacting());
    level = qualityController_.next();
  }
  const int rw = std::max(1, static_cast<int>(std::lround(width * level.resolutionScale)));
  const int rh = std::max(1, static_cast<int>(std::lround(height * level.resolutionScale)));
  settings.stepVoxels *= level.stepScale;
  stats.renderWidth = rw;
  stats.renderHeight = rh;
  return active_.technique->render(camera_, settings, rw, rh, 0.0);
}

void Viewer::drawOverlayLines(int width, int height) {
  const glm::dvec3 e = 0.5 * volume_->extent();
  if (gpu_->lineExtent != e) {
    // Box edges grey, then the x/y/z axes in red/green/blue from the
    // box's minimum corner (the voxel (0,0,0) corner).
    std::vector<float> v;
    auto add = [&v](glm::dvec3 p, glm::vec4 c) {
      v.insert(v.end(), {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z),
                         c.r, c.g, c.b, c.a});
    };
    const glm::vec4 grey(0.8f, 0.8f, 0.8f, 0.7f);
    for (int axis = 0; axis < 3; ++axis) {
      for (int i = 0; i < 4; ++i) {
        glm::dvec3 a(0.0);
        const int u = (axis + 1) % 3, w = (axis + 2) % 3;
        a[u] = (i & 1) ? e[u] : -e[u];
        a[w] = (i & 2) ? e[w] : -e[w];
        glm::dvec3 b = a;
        a[axis] = -e[axis];
        b[axis] = e[axis];
        add(a, grey);
        add(b, grey);
      }
    }
    const glm::vec4 axisColors[3] = {
        {1.0f, 0.25f, 0.25f, 1.0f}, {0.3f, 1.0f, 0.3f, 1.0f}, {0.35f, 0.55f, 1.0f, 1.0f}};
    for (int axis = 0; axis < 3; ++axis) {
      glm::dvec3 b = -e;
      b[axis] += 0.35 * 2.0 * e[axis];
      add(-e, axisColors[axis]);
      add(b, axisColors[axis]);
    }
    gpu_->lineVertices =
        gpu::Buffer::create(context_.ledger(), "overlay lines", gpu::BufferKind::Vertices,
                            v.size() * sizeof(float), v.data(), gpu::BufferUsage::Static);
    gpu_->lineVertexCount = static_cast<int>(v.size() / 7);
    gpu_->lineExtent = e;
  }
  const gpu::Program& p = gpu_->lines;
  p.use();
  p.set("u_viewProjection", viewProjection(camera_, static_cast<double>(width) / height));
  const int first = showBoundingBox ? 0 : 24;
  const int count = (showBoundingBox ? 24 : 0) + (showAxes ? 6 : 0);
  gpu::apply({.blend = gpu::Blend::StraightAlpha});
  gpu::drawArrays(gpu::Primitive::Lines, gpu_->lineVertices,
                  {{0, 3, 0}, {p.attributeLocation("a_color"), 4, 3}}, 7, first, count);
  gpu::apply({});
}

FrameStats Viewer::render(int width, int height, unsigned framebuffer, glm::ivec2 origin) {
  const auto t0 = std::chrono::steady_clock::now();
  FrameStats stats;
  controller_.setViewport(width, height);
  gpu::clearErrors();
  const glm::ivec4 box(origin, width, height);
  gpu::bindFramebuffer(framebuffer, box);
  if (!hasVolume()) {
    gpu::apply({.scissor = true, .scissorBox = box});
    gpu::clearColor(glm::vec4(glm::vec3(settings_.background), 1.0f));
    gpu::apply({});
    last_ = stats;
    return stats;
  }
  render::QualityLevel level;  // full quality
  const gpu::Texture& image = renderVolume(width, height, stats, level);

  gpu::bindFramebuffer(framebuffer, box);
  gpu::apply({});
  gpu_->present.use();
  image.bind(0);
  gpu_->present.set("u_image", 0);
  gpu_->triangle.draw();
  if (showBoundingBox || showAxes) drawOverlayLines(width, height);

  // glFinish does not wait in browsers: a read-back of one pixel does.
  std::uint8_t pixel[4];
  gpu::readPixelsRgba8({origin, 1, 1}, pixel);
  gpu::checkErrors("viewer frame");
  stats.ms = msSince(t0);
  if (quality == Quality::Adaptive) qualityController_.report(level, stats.ms);
  last_ = stats;
  return stats;
}

}  // namespace tessera::viewer
