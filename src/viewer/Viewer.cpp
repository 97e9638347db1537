#include "tessera/viewer/Viewer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/Histogram.h"
#include "tessera/core/HostBudget.h"
#include "tessera/core/Timing.h"
#include "tessera/gpu/DeviceSession.h"
#include "tessera/gpu/Draw.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/lod/InCoreVolumeSource.h"
#include "tessera/render/FusionTexture.h"
#include "tessera/render/HybridCompositor.h"
#include "tessera/viewer/CropHandles.h"

namespace tessera::viewer {

namespace {

constexpr int kHistogramBins = 256;
// Render-target size the plan reserves memory for (the largest frame we expect).
constexpr int kPlanImageSize = 1024;
constexpr int kSkipBlock = 8;
// The TF table size of a volume that is not shown as labels.
const int kValueLutSize = render::TechniqueOptions{}.lutSize;

glm::vec4 fullView() {
  return {0.0f, 0.0f, 1.0f, 1.0f};
}

// The part of a view that the volume box (centred at the origin, `extent`
// wide) covers, as fractions (x0, y0, x1, y1) of the view, padded by `pad`
// pixels: the bounding rectangle of the box's projected corners, with the
// rays of render/camera_ray.glsl. Rays outside it miss the box, so a pass
// scissored to it draws the same image. The whole view when a corner is not
// in front of a perspective eye.
glm::vec4 volumeScreenRegion(const Camera& camera, glm::dvec3 extent, int width, int height,
                             double pad) {
  const glm::dmat3 b = camera.basis();
  const glm::dvec3 eye = camera.eye();
  const double aspect = static_cast<double>(width) / height;
  const double tanHalfFov = std::tan(0.5 * camera.fovYDeg * glm::pi<double>() / 180.0);
  glm::dvec2 lo(1e300), hi(-1e300);
  for (int i = 0; i < 8; ++i) {
    const glm::dvec3 corner =
        0.5 * extent * glm::dvec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
    const glm::dvec3 v = corner - eye;
    glm::dvec2 ndc(glm::dot(v, b[0]), glm::dot(v, b[1]));
    if (camera.projection == Projection::Orthographic) {
      ndc /= glm::dvec2(camera.orthoHalfHeight() * aspect, camera.orthoHalfHeight());
    } else {
      const double depth = -glm::dot(v, b[2]);
      if (!(depth > 1e-6 * glm::length(extent))) return fullView();
      ndc /= glm::dvec2(depth * tanHalfFov * aspect, depth * tanHalfFov);
    }
    lo = glm::min(lo, ndc);
    hi = glm::max(hi, ndc);
  }
  const glm::dvec2 margin(pad / width, pad / height);
  const glm::dvec2 a = glm::clamp(0.5 * lo + 0.5 - margin, 0.0, 1.0);
  const glm::dvec2 c = glm::clamp(0.5 * hi + 0.5 + margin, 0.0, 1.0);
  if (!std::isfinite(a.x + a.y + c.x + c.y)) return fullView();
  return {static_cast<float>(a.x), static_cast<float>(a.y), static_cast<float>(c.x),
          static_cast<float>(c.y)};
}

glm::vec4 regionUnion(glm::vec4 a, glm::vec4 b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::max(a.z, b.z), std::max(a.w, b.w)};
}

}  // namespace

struct Viewer::Gpu {
  // Upscales the volume layer and composes the lines with it by depth
  // (Moser & Weiskopf 2008), as `tessera render --overlays` does.
  explicit Gpu(gpu::GlContext& context) : compositor(context) {}
  render::HybridCompositor compositor;
};

Viewer::Viewer(gpu::GlContext& context, const gpu::DeviceProfile& profile)
    : context_(context),
      limits_(gpu::applyProfile(profile, context)),
      volume_(std::make_shared<Volume>()),
      gpu_(std::make_unique<Gpu>(context)) {}

Viewer::~Viewer() {
  // GL objects go while the context is still current (the front end's job).
  active_ = {};
  gpu_.reset();
}

render::TechniqueOnVolume Viewer::createActive(const std::string& technique,
                                               const lod::VolumeSource& source) const {
  render::TechniqueOnVolume t =
      render::createTechnique(technique, context_, limits_, source,
                              {.imageSize = {kPlanImageSize, kPlanImageSize},
                               .skipBlock = kSkipBlock,
                               .lutSize = lutSize_});
  t.technique->setTransferFunction(tfEditor_.transferFunction());
  applyFusion(*t.technique);
  return t;
}

void Viewer::applyFusion(render::Technique& technique) const {
  fusionNote_.clear();
  try {
    if (fusion_) render::FusionTexture::checkDevice(limits_, *fusion_);
    technique.setFusion(fusion_);
  } catch (const InputError& e) {
    fusionNote_ = e.what();
  }
}

void Viewer::setFusion(std::shared_ptr<const FusedVolume> fused) {
  fusion_ = std::move(fused);
  if (active_.technique) applyFusion(*active_.technique);
}

void Viewer::setVolume(Volume volume, const std::string& name) {
  setVolume(std::make_shared<Volume>(std::move(volume)), name);
}

void Viewer::setVolume(std::shared_ptr<Volume> volume, const std::string& name) {
  if (!volume || !volume->hasData()) throw InputError(name + ": the volume has no voxels");
  const lod::InCoreVolumeSource source(std::move(volume));
  render::TechniqueOnVolume next;
  const bool wasLabels = labels_.has_value();
  if (wasLabels) lutSize_ = kValueLutSize;  // a new volume is not a label volume until setLabels
  try {
    next = createActive(techniqueName_, source);
  } catch (const BudgetError& e) {
    if (!hasVolume()) throw;
    if (wasLabels) lutSize_ = render::kLabelLutSize;
    throw BudgetError(name + ": does not fit the GPU budget next to the current volume (" +
                      formatBytes(context_.ledger().budget()) + "): " + e.what());
  } catch (...) {
    if (wasLabels) lutSize_ = render::kLabelLutSize;
    throw;
  }
  if (wasLabels) {
    labels_.reset();
    settings_.nearest = false;
    tfEditor_.loadPreset("mr-default");
    next.technique->setTransferFunction(tfEditor_.transferFunction());
  }
  // Everything worked: swap in.
  active_ = std::move(next);
  pending_ = {};
  drawn_ = {};
  frameMsPerPixel_ = stripMsPerWeight_ = 0.0;
  volume_ = source.level(glm::ivec3(1));
  volumeName_ = name;
  ++volumeRevision_;
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
  pending_ = {};
  drawn_ = {};
  frameMsPerPixel_ = stripMsPerWeight_ = 0.0;
  techniqueName_ = name;
}

void Viewer::recreateActive() {
  const lod::InCoreVolumeSource source(volume_);
  active_ = {};  // the old upload goes first: both may not fit the budget
  active_ = createActive(techniqueName_, source);
  uploadedTfRevision_ = tfEditor_.revision();
  pending_ = {};
  drawn_ = {};
  frameMsPerPixel_ = stripMsPerWeight_ = 0.0;
}

void Viewer::setLabels(render::LabelTable table) {
  if (!hasVolume()) throw InputError("labels: no volume loaded");
  if (!labels_) {
    Volume check = *volume_;  // InputError before anything changes
    render::prepareLabelVolume(check);
    volume_->setWindow(check.window());
    if (active_.upload.volume != volume_) active_.upload.volume->setWindow(check.window());
    render::applyLabelSettings(settings_);
    lutSize_ = render::kLabelLutSize;
    labels_ = std::move(table);
    tfEditor_.setTransferFunction(labels_->toTransferFunction());
    recreateActive();
    updateHistogram();
    return;
  }
  labels_ = std::move(table);
  tfEditor_.setTransferFunction(labels_->toTransferFunction());
}

void Viewer::clearLabels(const std::string& tf) {
  if (!labels_) return;
  labels_.reset();
  settings_.nearest = false;
  lutSize_ = kValueLutSize;
  tfEditor_.loadPreset(tf);
  recreateActive();
  resetWindow();
}

void Viewer::setLabelVisible(int value, bool visible) {
  if (!labels_) return;
  const auto it = labels_->labels.find(value);
  if (it == labels_->labels.end() || it->second.visible == visible) return;
  it->second.visible = visible;
  tfEditor_.setTransferFunction(labels_->toTransferFunction());
}

void Viewer::setAllLabelsVisible(bool visible) {
  if (!labels_) return;
  for (auto& [value, label] : labels_->labels) label.visible = visible;
  tfEditor_.setTransferFunction(labels_->toTransferFunction());
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

// The settings a frame renders with: the user's, plus the clip plane that
// follows the camera when asked.
RenderSettings Viewer::frameSettings() const {
  RenderSettings settings = settings_;
  if (clipPlaneFollowsCamera &&
      settings.clipping.planes.size() < static_cast<std::size_t>(kMaxClipPlanes)) {
    settings.clipping.planes.push_back(cameraFacingPlane(camera_, followingPlaneDistance));
  }
  return settings;
}

void Viewer::syncTransferFunction() {
  if (uploadedTfRevision_ != tfEditor_.revision()) {
    active_.technique->setTransferFunction(tfEditor_.transferFunction());
    uploadedTfRevision_ = tfEditor_.revision();
  }
}

Viewer::VolumePass Viewer::volumePass(int width, int height,
                                      const render::QualityLevel& level) const {
  VolumePass p;
  p.settings = frameSettings();
  double scale = level.resolutionScale;
  const double pixels = static_cast<double>(width) * height;
  if (maxVolumePixels > 0 && pixels > maxVolumePixels) scale *= std::sqrt(maxVolumePixels / pixels);
  p.width = std::max(1, static_cast<int>(std::lround(width * scale)));
  p.height = std::max(1, static_cast<int>(std::lround(height * scale)));
  p.settings.stepVoxels *= level.stepScale;
  // Over transparent black: RGB is the colour over black, A the opacity the
  // compositor weighs lines behind the volume with; it adds the background.
  p.settings.background = glm::dvec4(0.0);
  return p;
}

void Viewer::compose(const gpu::Texture& image, int width, int height, unsigned framebuffer,
                     glm::ivec2 origin) {
  const std::vector<render::OverlayLine> lines = overlayLines();
  gpu_->compositor.setOverlayLines(lines);
  const glm::ivec4 box(origin, width, height);
  if (lines.empty()) {
    // Without lines, what lies outside the volume's part of the view is the
    // background: a clear, and the composite pass only where the volume is
    // (padded by the upscaled layer's bilinear footprint).
    gpu::bindFramebuffer(framebuffer, box);
    gpu::apply({.scissor = true, .scissorBox = box});
    gpu::clearColor(glm::vec4(settings_.background));
    gpu::apply({});
    const double upscale = std::max(static_cast<double>(width) / image.width(),
                                    static_cast<double>(height) / image.height());
    const gpu::RegionScope region(volumeScreenRegion(camera_, volume_->extent(), width, height,
                                                     2.0 + 2.0 * std::ceil(upscale)));
    gpu_->compositor.composeInto(image, camera_, glm::vec4(settings_.background), volume_->extent(),
                                 framebuffer, box);
  } else {
    gpu_->compositor.composeInto(image, camera_, glm::vec4(settings_.background), volume_->extent(),
                                 framebuffer, box);
  }
  // glFinish does not wait in browsers: a read-back of one pixel does.
  std::uint8_t pixel[4];
  gpu::readPixelsRgba8({origin, 1, 1}, pixel);
  gpu::checkErrors("viewer frame");
}

// The ray caster's rays outside the volume's part of the view miss the box
// and write transparent black, so a frame scissored to that part draws the
// same image, provided the target holds nothing outside it from before: the
// part drawn is the union of this frame's and the last one's, and the whole
// target when it was not this technique's last frame at this size.
const gpu::Texture& Viewer::renderVolume(const VolumePass& pass) {
  render::Technique* technique = active_.technique.get();
  if (!render::TechniqueRegistry::global().find(techniqueName_).scissorsToVolume) {
    drawn_ = {};
    return technique->render(camera_, pass.settings, pass.width, pass.height, 0.0);
  }
  const glm::vec4 region =
      volumeScreenRegion(camera_, volume_->extent(), pass.width, pass.height, 2.0);
  const bool sameTarget =
      drawn_.technique == technique && drawn_.width == pass.width && drawn_.height == pass.height;
  const gpu::RegionScope scope(sameTarget ? regionUnion(region, drawn_.region) : fullView());
  const gpu::Texture& image =
      technique->render(camera_, pass.settings, pass.width, pass.height, 0.0);
  drawn_ = {.technique = technique, .width = pass.width, .height = pass.height, .region = region};
  return image;
}

FrameStats Viewer::presentFrame(int width, int height, unsigned framebuffer, glm::ivec2 origin,
                                const render::QualityLevel& level) {
  const auto t0 = std::chrono::steady_clock::now();
  const VolumePass pass = volumePass(width, height, level);
  const gpu::Texture& image = renderVolume(pass);
  compose(image, width, height, framebuffer, origin);
  FrameStats stats;
  stats.ms = msSince(t0);
  stats.renderWidth = pass.width;
  stats.renderHeight = pass.height;
  return stats;
}

std::vector<render::OverlayLine> Viewer::overlayLines() const {
  std::vector<render::OverlayLine> lines;
  const glm::dvec3 e = 0.5 * volume_->extent();
  if (showBoundingBox) {
    const glm::vec4 grey(0.6f, 0.6f, 0.6f, 1.0f);
    for (int axis = 0; axis < 3; ++axis) {
      for (int i = 0; i < 4; ++i) {
        glm::dvec3 a(0.0);
        const int u = (axis + 1) % 3, w = (axis + 2) % 3;
        a[u] = (i & 1) ? e[u] : -e[u];
        a[w] = (i & 2) ? e[w] : -e[w];
        glm::dvec3 b = a;
        a[axis] = -e[axis];
        b[axis] = e[axis];
        lines.push_back({a, b, grey});
      }
    }
  }
  if (showAxes) {
    // x/y/z in red/green/blue from the box's minimum corner (voxel (0,0,0)).
    const glm::vec4 axisColors[3] = {
        {1.0f, 0.25f, 0.25f, 1.0f}, {0.3f, 1.0f, 0.3f, 1.0f}, {0.35f, 0.55f, 1.0f, 1.0f}};
    for (int axis = 0; axis < 3; ++axis) {
      glm::dvec3 b = -e;
      b[axis] += 0.35 * 2.0 * e[axis];
      lines.push_back({-e, b, axisColors[axis]});
    }
  }
  lines.insert(lines.end(), extraLines.begin(), extraLines.end());
  return lines;
}

FrameStats Viewer::render(int width, int height, unsigned framebuffer, glm::ivec2 origin) {
  pending_ = {};
  controller_.setViewport(width, height);
  gpu::clearErrors();
  const glm::ivec4 box(origin, width, height);
  gpu::bindFramebuffer(framebuffer, box);
  if (!hasVolume()) {
    gpu::apply({.scissor = true, .scissorBox = box});
    gpu::clearColor(glm::vec4(glm::vec3(settings_.background), 1.0f));
    gpu::apply({});
    last_ = FrameStats();
    return last_;
  }
  syncTransferFunction();
  render::QualityLevel level;  // full quality
  if (quality == Quality::Adaptive) {
    qualityController_.setInteracting(controller_.interacting());
    level = qualityController_.next();
  }
  if (progressive && level.full()) {
    const VolumePass full = volumePass(width, height, level);
    const double pixels = static_cast<double>(full.width) * full.height;
    if (!(frameMsPerPixel_ > 0.0) || frameMsPerPixel_ * pixels > frameBudgetMs) {
      // A preview now, the full frame strip by strip in refine().
      qualityController_.setInteracting(true);
      const render::QualityLevel preview = qualityController_.next();
      qualityController_.setInteracting(false);
      FrameStats stats = presentFrame(width, height, framebuffer, origin, preview);
      qualityController_.report(preview, stats.ms);
      stats.complete = false;
      pending_ = {.active = true,
                  .width = width,
                  .height = height,
                  .framebuffer = framebuffer,
                  .origin = origin,
                  .pass = full,
                  .costs = {}};
      last_ = stats;
      return stats;
    }
  }
  FrameStats stats = presentFrame(width, height, framebuffer, origin, level);
  if (quality == Quality::Adaptive) qualityController_.report(level, stats.ms);
  if (level.full()) {
    frameMsPerPixel_ = stats.ms / (static_cast<double>(stats.renderWidth) * stats.renderHeight);
  }
  last_ = stats;
  return stats;
}

FrameStats Viewer::refine() {
  if (!pending_.active) return last_;
  const auto t0 = std::chrono::steady_clock::now();
  Pending& p = pending_;
  const double pixels = static_cast<double>(p.pass.width) * p.pass.height;
  const double minStrip = 1.0 / p.pass.height;
  const gpu::Texture* image = nullptr;
  gpu::clearErrors();
  drawn_ = {};  // the strips write the whole target
  // One strip per call, as many rows as the budget affords at the cost of
  // the strips before (a single draw keeps the per-call overhead of
  // multi-pass techniques, such as the slicers' hundreds of slices, once).
  // The cost is per unit of what the rows are expected to cost
  // (render::RowCosts: rows across what the technique draws, the volume's
  // box or the slicer's proxy, are dear, those beside it cheap), not per
  // pixel: a cost learnt on the rows below the volume would size a strip
  // across it several budgets long.
  if (p.costs.empty()) {
    p.costs = render::RowCosts(camera_, volume().extent(), p.pass.width, p.pass.height,
                               active_.technique->footprint());
  }
  double strip = stripMsPerWeight_ > 0.0
                     ? p.costs.reach(p.done, frameBudgetMs / stripMsPerWeight_) - p.done
                     : 1.0 / 16.0;
  strip = std::clamp(strip, minStrip, 1.0 - p.done);
  if (1.0 - (p.done + strip) < 0.5 * minStrip) strip = 1.0 - p.done;
  {
    const gpu::RegionScope region(
        glm::vec4(0.0f, static_cast<float>(p.done), 1.0f, static_cast<float>(p.done + strip)));
    image = &active_.technique->render(camera_, p.pass.settings, p.pass.width, p.pass.height, 0.0);
    std::uint8_t pixel[4];
    gpu::readPixelsRgba8({0, 0, 1, 1}, pixel);  // waits for the strip (browsers too)
  }
  const double ms = msSince(t0);
  // Smoothed: a strip's time varies with what its rows cover.
  const double weight = p.costs.weight(p.done, p.done + strip);
  if (weight > 0.0) {
    const double perWeight = ms / weight;
    stripMsPerWeight_ = stripMsPerWeight_ > 0.0 ? 0.5 * (stripMsPerWeight_ + perWeight) : perWeight;
  }
  p.ms += ms;
  p.done = p.done + strip >= 1.0 - 1e-9 ? 1.0 : p.done + strip;
  gpu::checkErrors("progressive frame");
  FrameStats stats;
  stats.renderWidth = p.pass.width;
  stats.renderHeight = p.pass.height;
  stats.complete = p.done >= 1.0;
  if (stats.complete) {
    compose(*image, p.width, p.height, p.framebuffer, p.origin);
    frameMsPerPixel_ = p.ms / pixels;
    pending_ = {};
  }
  stats.ms = msSince(t0);
  last_ = stats;
  return stats;
}

}  // namespace tessera::viewer
