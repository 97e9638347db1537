#pragma once
// Where slicing techniques composite: an accumulation target cleared to
// transparent black, slices blended into it front to back, then a resolve
// pass that composites the background (DESIGN.md, Rendering semantics) into
// the RGBA8 image the caller reads.
//
// Blending is C += (1 - A) * c_premultiplied, A += (1 - A) * a, i.e.
// glBlendFuncSeparate(ONE_MINUS_DST_ALPHA, ONE, ONE_MINUS_DST_ALPHA, ONE).
// (Noguera et al. 2012, section 3.2, use ONE, ONE for alpha, which sums the
// slices' alphas instead of compositing them; with the distance-corrected
// opacities used here that would not match the ray caster.)
// The target is RGBA16F where the device renders to float targets (ES 3 with
// EXT_color_buffer_float): hundreds of thin slices rounded to 8 bits each
// would drift. ES 2 devices accumulate in RGBA8, as the papers' devices did;
// slice3d then blends slabs of planes composited in its shader
// (Slice3DRenderer.h), so that fewer, larger contributions are rounded.
// MIP blends with GL_MAX (ES 3, or ES 2 with EXT_blend_minmax): slices write
// (n * inside, 0, 0, inside) and the resolve pass classifies the maximum.
// Several channels' maxima (docs/channels.md) take two targets: channels 0-3
// in the first, 4-5 and the hit flag in a second (beginSecond), drawn one
// after the other (ES 2 has no multiple render targets), and a resolve pass
// of the caller's that colours them (resolveWith).
#include <optional>
#include <string>

#include "tessera/core/Image.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/Program.h"

namespace tessera::render {

class SliceAccumulator {
 public:
  // `halfFloat`: accumulate in half floats where the context renders to
  // them (nullopt: whenever it does; false: RGBA8, as a device profile
  // without float render targets has it).
  explicit SliceAccumulator(gpu::GlContext& context, std::optional<bool> halfFloat = std::nullopt);

  // (Re)allocates the targets for the size, binds and clears the
  // accumulation target and sets the blending for `mode`. GpuError for MIP
  // on an ES 2 context without EXT_blend_minmax.
  void begin(int width, int height, RenderMode mode);
  // Composites into the RGBA8 image and waits for it (glFinish). For MIP,
  // `lut` is the TF table (entries as in render/classify.glsl).
  void resolve(const RenderSettings& settings, const gpu::Texture* lut, int lutEntries);
  // After begin(): a second accumulation target of the same size and format,
  // bound, cleared and set to the same blending.
  void beginSecond(RenderMode mode);
  // Resolves with the caller's `program`, in use with its own uniforms set:
  // the first and second targets at units firstUnit and firstUnit + 1
  // (u_peaks0, u_peaks1), u_viewport and u_background as in resolve().
  void resolveWith(const gpu::Program& program, int firstUnit, const RenderSettings& settings);
  // The last resolved frame, top row first.
  Image readImage() const;
  // The RGBA8 texture holding the last resolved frame (row 0 at the bottom).
  const gpu::Texture& colorTexture() const { return image_.color(); }

  // "RGBA16F" or "RGBA8".
  std::string accumulationFormat() const {
    return floatTarget_ ? gpu::texelFormatName(*floatTarget_) : "RGBA8";
  }
  // Whether every blend rounds to 8 bits (no half-float target).
  bool roundsTo8Bits() const { return !floatTarget_; }
  std::uint64_t ownTextureBytes() const;

 private:
  const gpu::Program& resolveProgram(RenderMode mode);

  gpu::GlContext& context_;
  std::optional<gpu::TexelFormat> floatTarget_;  // the half-float target, if any
  gpu::Framebuffer accumulation_;
  gpu::Framebuffer second_;  // channels 4-5 and the hit flag (beginSecond)
  gpu::Framebuffer image_;
  gpu::FullscreenTriangle triangle_;
  gpu::Program compositeResolve_;
  gpu::Program mipResolve_;
};

}  // namespace tessera::render
