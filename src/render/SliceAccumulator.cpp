#include "tessera/render/SliceAccumulator.h"

#include "render/FramebufferImage.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/Draw.h"

namespace tessera::render {

SliceAccumulator::SliceAccumulator(gpu::GlContext& context, std::optional<bool> halfFloat)
    : context_(context) {
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(context.caps());
  // Half floats where the context renders to them (ES 3: RGBA16F; ES 2:
  // EXT_color_buffer_half_float) and the device allows them, so that thin
  // slices' small premultiplied contributions are not rounded to 8 bits one
  // by one; RGBA8 otherwise.
  if (limits.halfFloatRenderTargets && halfFloat.value_or(true)) {
    floatTarget_ = context.caps().api == gpu::ApiLevel::Gles3 ? gpu::TexelFormat::RGBA16F
                                                              : gpu::TexelFormat::RgbaHalfUnsized;
  }
  triangle_ = gpu::FullscreenTriangle(context.ledger());
}

std::uint64_t SliceAccumulator::ownTextureBytes() const {
  return accumulation_.color().bytes() + image_.color().bytes() +
         (second_.id() != 0 ? second_.color().bytes() : 0);
}

const gpu::Program& SliceAccumulator::resolveProgram(RenderMode mode) {
  gpu::Program& p = mode == RenderMode::Mip ? mipResolve_ : compositeResolve_;
  if (p.id() != 0) return p;
  const gpu::ApiLevel api = context_.caps().api;
  std::vector<gpu::ShaderPart> frag{gpu::shaderPreamble(api, true,
                                                        mode == RenderMode::Mip
                                                            ? std::vector<std::string>{"MODE_MIP 1"}
                                                            : std::vector<std::string>{})};
  if (mode == RenderMode::Mip) frag.push_back(gpu::embeddedShaderPart("render/classify.glsl"));
  frag.push_back(gpu::embeddedShaderPart("render/slice_resolve.frag.glsl"));
  p = gpu::Program::build(
      mode == RenderMode::Mip ? "slice resolve (mip)" : "slice resolve",
      {gpu::shaderPreamble(api, false, {}), gpu::embeddedShaderPart("render/fullscreen.vert.glsl")},
      frag);
  return p;
}

void SliceAccumulator::begin(int width, int height, RenderMode mode) {
  const int maxSize = context_.caps().maxRenderbufferSize;
  if (width <= 0 || height <= 0 || width > maxSize || height > maxSize) {
    throw InputError("image size " + std::to_string(width) + "x" + std::to_string(height) +
                     " is outside 1.." + std::to_string(maxSize));
  }
  if (mode == RenderMode::Mip && context_.caps().api == gpu::ApiLevel::Gles2 &&
      !context_.caps().has("GL_EXT_blend_minmax")) {
    throw GpuError(
        "MIP by slicing needs max blending (GL_EXT_blend_minmax), which this ES 2.0 "
        "context lacks; use --technique raycast");
  }
  if (accumulation_.id() == 0 || accumulation_.width() != width ||
      accumulation_.height() != height) {
    accumulation_ = gpu::Framebuffer();
    second_ = gpu::Framebuffer();
    image_ = gpu::Framebuffer();
    const gpu::TexelFormat rgba8 = gpu::rgba8For(context_.caps().api);
    accumulation_ = gpu::Framebuffer::create(context_.ledger(), "slice accumulation", width, height,
                                             floatTarget_.value_or(rgba8));
    // Read at texel centres anyway; NEAREST also keeps an ES 2 half-float
    // target complete where half floats do not filter.
    accumulation_.color().setFilter(gpu::Filter::Nearest);
    // Read back at texel centres (gl_FragCoord / size), where linear
    // filtering returns the texel itself.
    image_ = gpu::Framebuffer::create(context_.ledger(), "slice image", width, height, rgba8);
  }
  accumulation_.bind();
  gpu::apply({});
  gpu::clearColor(glm::vec4(0.0f));
  // Front to back (DESIGN.md): the destination's transmittance 1 - A weighs
  // each new premultiplied slice colour and alpha; MIP keeps the maximum.
  gpu::apply({.blend = mode == RenderMode::Mip ? gpu::Blend::Max : gpu::Blend::FrontToBack});
}

void SliceAccumulator::beginSecond(RenderMode mode) {
  if (second_.id() == 0) {
    second_ = gpu::Framebuffer::create(context_.ledger(), "slice accumulation (channels 4-5)",
                                       accumulation_.width(), accumulation_.height(),
                                       floatTarget_.value_or(gpu::rgba8For(context_.caps().api)));
    second_.color().setFilter(gpu::Filter::Nearest);
  }
  second_.bind();
  gpu::apply({});
  gpu::clearColor(glm::vec4(0.0f));
  gpu::apply({.blend = mode == RenderMode::Mip ? gpu::Blend::Max : gpu::Blend::FrontToBack});
}

void SliceAccumulator::resolveWith(const gpu::Program& program, int firstUnit,
                                   const RenderSettings& settings) {
  if (second_.id() == 0) throw GpuError("slice resolve: the second target was not drawn");
  gpu::apply({});
  image_.bind();
  program.use();
  accumulation_.color().bind(firstUnit);
  program.set("u_peaks0", firstUnit);
  second_.color().bind(firstUnit + 1);
  program.set("u_peaks1", firstUnit + 1);
  program.set("u_viewport", glm::vec2(image_.width(), image_.height()));
  program.set("u_background", glm::vec4(settings.background));
  triangle_.draw();
  gpu::finish();
  gpu::checkErrors("slice rendering (channels)");
}

void SliceAccumulator::resolve(const RenderSettings& settings, const gpu::Texture* lut,
                               int lutEntries) {
  gpu::apply({});
  image_.bind();
  const gpu::Program& p = resolveProgram(settings.mode);
  p.use();
  accumulation_.color().bind(0);
  p.set("u_accumulation", 0);
  p.set("u_viewport", glm::vec2(image_.width(), image_.height()));
  p.set("u_background", glm::vec4(settings.background));
  if (settings.mode == RenderMode::Mip) {
    if (lut == nullptr) throw GpuError("slice resolve: MIP needs the transfer-function table");
    lut->bind(1);
    p.set("u_tf", 1);
    p.set("u_tfSize", static_cast<float>(lutEntries));
  }
  triangle_.draw();
  gpu::finish();
  gpu::checkErrors("slice rendering");
}

Image SliceAccumulator::readImage() const {
  return render::readImage(image_);
}

}  // namespace tessera::render
