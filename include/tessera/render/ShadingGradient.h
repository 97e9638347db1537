#pragma once
// Where a layout-based technique's shaded samples take the gradient
// (layout/GradientTexture.h): the plan (precomputed RGBA8 texture or central
// differences on the fly, with its reason), the texture built on the first
// shaded frame that uses it, and the program's defines, parts and binding.
// The ray caster and slice3d each own one.
#include <string>
#include <vector>

#include "tessera/core/RenderSettings.h"
#include "tessera/core/Volume.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/gpu/Program.h"
#include "tessera/layout/GradientTexture.h"
#include "tessera/layout/Layout.h"

namespace tessera::render {

class ShadingGradient {
 public:
  // `ownUnits`: the technique's texture units besides the layout's; the
  // texture needs one more. `volume` and `layout` must outlive this object.
  ShadingGradient(gpu::GlContext& context, const Volume& volume, const layout::Layout& layout,
                  int ownUnits);

  // Plans anew (auto: the plan's choice); InputError for Precomputed where
  // it cannot be had.
  void setWish(layout::GradientWish wish);
  const layout::GradientPlan& plan() const { return plan_; }
  const layout::GradientTexture& texture() const { return texture_; }
  // Whether frames with these settings shade from the precomputed texture.
  bool precomputed(const RenderSettings& settings) const;

  // Whether lit samples take their value from the texture too (its alpha:
  // one fetch per lit sample instead of two; render/sample.glsl). Known once
  // prepare() built the texture.
  bool valuesFromGradient(const RenderSettings& settings) const;

  // Builds the texture when these settings need it.
  void prepare(const RenderSettings& settings);
  void addDefines(const RenderSettings& settings, std::vector<std::string>& defines) const;
  // The texture's GLSL part (ES 3 only); it goes before the layout's seam parts.
  void addParts(std::vector<gpu::ShaderPart>& parts) const;
  // Binds the texture at `unit` when these settings use it; returns the units used.
  int bind(const gpu::Program& program, int unit, const RenderSettings& settings) const;
  std::uint64_t bytes() const { return texture_.bytes(); }

 private:
  gpu::GlContext& context_;
  const Volume& volume_;
  const layout::Layout& layout_;
  int ownUnits_;
  layout::GradientPlan plan_;
  layout::GradientTexture texture_;
};

}  // namespace tessera::render
