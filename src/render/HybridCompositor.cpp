#include "tessera/render/HybridCompositor.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include "render/FramebufferImage.h"
#include "tessera/core/Error.h"
#include "tessera/core/Timing.h"
#include "tessera/gpu/Draw.h"

namespace tessera::render {

namespace {

const char* methodDefine(OverlayOpacity m) {
  switch (m) {
    case OverlayOpacity::Alpha:
      return "METHOD_ALPHA 1";
    case OverlayOpacity::TwoPass:
      return "METHOD_TWO_PASS 1";
    case OverlayOpacity::LumaAverage:
      return "METHOD_LUMA_AVG 1";
    case OverlayOpacity::Luma601:
      return "METHOD_LUMA_601 1";
  }
  return "METHOD_ALPHA 1";
}

}  // namespace

std::string overlayOpacityName(OverlayOpacity method) {
  switch (method) {
    case OverlayOpacity::Alpha:
      return "alpha";
    case OverlayOpacity::TwoPass:
      return "two-pass";
    case OverlayOpacity::LumaAverage:
      return "luma-avg";
    case OverlayOpacity::Luma601:
      return "luma-601";
  }
  return "alpha";
}

std::vector<OverlayOpacity> allOverlayOpacities() {
  return {OverlayOpacity::Alpha, OverlayOpacity::TwoPass, OverlayOpacity::LumaAverage,
          OverlayOpacity::Luma601};
}

OverlayOpacity parseOverlayOpacity(const std::string& name) {
  for (OverlayOpacity m : allOverlayOpacities()) {
    if (overlayOpacityName(m) == name) return m;
  }
  throw InputError("--line-attenuation '" + name +
                   "': expected alpha, two-pass, luma-avg or luma-601");
}

OffscreenSize OffscreenSize::ofFactor(double f) {
  if (!(f > 0.0 && f <= 1.0)) {
    char got[32];
    std::snprintf(got, sizeof got, "%g", f);
    throw InputError(std::string("--offscreen factor must be in (0, 1], got ") + got);
  }
  OffscreenSize s;
  s.factor = f;
  return s;
}

OffscreenSize OffscreenSize::ofSize(int width, int height) {
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384) {
    throw InputError("offscreen size " + std::to_string(width) + "x" + std::to_string(height) +
                     " must be 1..16384 per axis");
  }
  OffscreenSize s;
  s.fixed = {width, height};
  return s;
}

OffscreenSize OffscreenSize::parse(const std::string& text) {
  if (text == "full") return ofFactor(1.0);
  int w = 0, h = 0;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%dx%d%c", &w, &h, &tail) == 2) return ofSize(w, h);
  double f = 0.0;
  if (std::sscanf(text.c_str(), "%lf%c", &f, &tail) == 1) return ofFactor(f);
  throw InputError("--offscreen '" + text +
                   "': expected WIDTHxHEIGHT (e.g. 128x128, 256x512), a factor in (0,1] "
                   "(e.g. 0.25) or full");
}

glm::ivec2 OffscreenSize::resolve(int screenWidth, int screenHeight) const {
  if (fixed.x > 0) return fixed;
  return {std::max(1, static_cast<int>(std::lround(screenWidth * factor))),
          std::max(1, static_cast<int>(std::lround(screenHeight * factor)))};
}

std::string OffscreenSize::describe() const {
  if (fixed.x > 0) return std::to_string(fixed.x) + "x" + std::to_string(fixed.y);
  char buf[32];
  std::snprintf(buf, sizeof buf, "factor %g", factor);
  return buf;
}

HybridCompositor::HybridCompositor(gpu::GlContext& context)
    : context_(context), overlay_(context), triangle_(context.ledger()) {
  const gpu::ApiLevel api = context.caps().api;
  composite_ = gpu::Program::build(
      "hybrid composite",
      {gpu::shaderPreamble(api, false, {}), gpu::embeddedShaderPart("render/fullscreen.vert.glsl")},
      {gpu::shaderPreamble(api, true, {}),
       gpu::embeddedShaderPart("render/hybrid_composite.frag.glsl")});
}

const gpu::Program& HybridCompositor::resolveProgram(const std::string& define) {
  for (const auto& [key, program] : resolvePrograms_) {
    if (key == define) return program;
  }
  const gpu::ApiLevel api = context_.caps().api;
  gpu::Program p = gpu::Program::build(
      "hybrid resolve(" + define + ")",
      {gpu::shaderPreamble(api, false, {}), gpu::embeddedShaderPart("render/fullscreen.vert.glsl")},
      {gpu::shaderPreamble(api, true, {define}),
       gpu::embeddedShaderPart("render/hybrid_resolve.frag.glsl")});
  resolvePrograms_.emplace_back(define, std::move(p));
  return resolvePrograms_.back().second;
}

namespace {

void ensureTarget(gpu::GlContext& context, gpu::Framebuffer& fb, const char* label, int width,
                  int height) {
  if (fb.id() != 0 && fb.width() == width && fb.height() == height) return;
  fb = gpu::Framebuffer();
  fb = gpu::Framebuffer::create(context.ledger(), label, width, height,
                                gpu::rgba8For(context.caps().api));
}

}  // namespace

void HybridCompositor::render(Technique& technique, const Camera& camera,
                              const RenderSettings& settings, glm::dvec3 volumeExtent, int width,
                              int height, const HybridOptions& options) {
  if (width <= 0 || height <= 0) throw InputError("hybrid: image size must be positive");
  const auto tStart = std::chrono::steady_clock::now();
  const glm::ivec2 low = options.offscreen.resolve(width, height);
  const double aspect = static_cast<double>(width) / height;
  timings_ = HybridTimings();
  timings_.offscreen = low;

  // 1. The volume at the offscreen size, and its opacity estimate.
  RenderSettings s = settings;
  const gpu::Texture* volume = nullptr;
  if (options.opacity == OverlayOpacity::TwoPass) {
    s.background = glm::dvec4(1.0, 1.0, 1.0, 1.0);
    const gpu::Texture& overWhite = technique.render(camera, s, low.x, low.y, aspect);
    // The technique reuses its target, so keep the first render.
    const glm::ivec2 whiteSize(overWhite.width(), overWhite.height());
    ensureTarget(context_, white_, "hybrid over-white copy", whiteSize.x, whiteSize.y);
    white_.bind();
    const gpu::Program& copy = resolveProgram("METHOD_COPY 1");
    copy.use();
    overWhite.bind(0);
    copy.set("u_volume", 0);
    copy.set("u_size", glm::vec2(whiteSize));
    gpu::apply({});
    triangle_.draw();
    s.background = glm::dvec4(0.0, 0.0, 0.0, 1.0);
    volume = &technique.render(camera, s, low.x, low.y, aspect);
    timings_.volumePasses = 2;
  } else {
    // Transparent black: RGB is the colour over black, A the accumulated opacity.
    s.background = glm::dvec4(0.0);
    volume = &technique.render(camera, s, low.x, low.y, aspect);
    timings_.volumePasses = 1;
  }
  // A technique may render another shape than asked (the slicers):
  // the layer follows its texture, and is stretched to the screen anyway.
  const glm::ivec2 rendered(volume->width(), volume->height());
  timings_.rendered = rendered;
  ensureTarget(context_, resolved_, "hybrid volume layer", rendered.x, rendered.y);
  resolved_.bind();
  const gpu::Program& resolve = resolveProgram(methodDefine(options.opacity));
  resolve.use();
  volume->bind(0);
  resolve.set("u_volume", 0);
  if (options.opacity == OverlayOpacity::TwoPass) {
    white_.color().bind(1);
    resolve.set("u_white", 1);
  }
  resolve.set("u_size", glm::vec2(rendered));
  gpu::apply({});
  triangle_.draw();
  gpu::finish();
  timings_.volumeMs = msSince(tStart);

  // 2. The lines at full resolution.
  const auto tOverlay = std::chrono::steady_clock::now();
  const bool hasLines = !lines_.empty();
  if (hasLines) overlay_.draw(lines_, camera, width, height, volumeExtent);
  gpu::finish();
  timings_.overlayMs = msSince(tOverlay);

  // 3. Upscale and compose at full resolution.
  const auto tComposite = std::chrono::steady_clock::now();
  ensureTarget(context_, image_, "hybrid image", width, height);
  image_.bind();
  drawComposite(resolved_.color(), glm::vec4(settings.background), width, height, {0, 0});
  gpu::finish();
  gpu::checkErrors("hybrid compositing");
  timings_.compositeMs = msSince(tComposite);
  timings_.totalMs = msSince(tStart);
}

void HybridCompositor::drawComposite(const gpu::Texture& volumeLayer, glm::vec4 background,
                                     int width, int height, glm::ivec2 origin) {
  const bool hasLines = !lines_.empty();
  composite_.use();
  composite_.set("u_viewport", glm::vec2(width, height));
  composite_.set("u_origin", glm::vec2(origin));
  composite_.set("u_background", background);
  volumeLayer.bind(0);
  composite_.set("u_volume", 0);
  composite_.set("u_hasLines", hasLines ? 1.0f : 0.0f);
  // (Without lines the sampler must still name a unit with a 2D texture.)
  (hasLines ? overlay_.colorTexture() : volumeLayer).bind(1);
  composite_.set("u_lineColor", 1);
  gpu::apply({});
  triangle_.draw();
}

void HybridCompositor::composeInto(const gpu::Texture& volumeLayer, const Camera& camera,
                                   glm::vec4 background, glm::dvec3 volumeExtent,
                                   unsigned framebuffer, glm::ivec4 box) {
  if (box.z <= 0 || box.w <= 0) throw InputError("hybrid: image size must be positive");
  if (!lines_.empty()) overlay_.draw(lines_, camera, box.z, box.w, volumeExtent);
  gpu::bindFramebuffer(framebuffer, box);
  drawComposite(volumeLayer, background, box.z, box.w, {box.x, box.y});
  gpu::checkErrors("hybrid compositing");
}

Image HybridCompositor::readImage() const {
  return render::readImage(image_);
}

Image HybridCompositor::readOpacityLayer() const {
  return render::readImage(resolved_);
}

}  // namespace tessera::render
