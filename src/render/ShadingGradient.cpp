#include "tessera/render/ShadingGradient.h"

#include "tessera/core/Error.h"
#include "tessera/render/ShadingUniforms.h"

namespace tessera::render {

ShadingGradient::ShadingGradient(gpu::GlContext& context, const Volume& volume,
                                 const layout::Layout& layout, int ownUnits)
    : context_(context), volume_(volume), layout_(layout), ownUnits_(ownUnits) {
  setWish(layout::GradientWish::Auto);
}

void ShadingGradient::setWish(layout::GradientWish wish) {
  const gpu::DeviceCaps& caps = context_.caps();
  if (layout_.textureUnits() + ownUnits_ + 1 > caps.maxTextureUnits) {
    if (wish == layout::GradientWish::Precomputed) {
      throw InputError("--gradient precomputed: no texture unit left for a gradient texture");
    }
    plan_ = layout::GradientPlan();
    plan_.reason =
        "on the fly (central differences, 6 fetches per lit sample): no texture unit left for a "
        "gradient texture";
  } else {
    // The budget next to everything allocated but a texture this replaces.
    plan_ = layout::planGradient(wish, layout_.volumeDims(), layout_.name(), caps.api,
                                 caps.max3DTextureSize, context_.ledger().budget(),
                                 context_.ledger().totalBytes() - texture_.bytes());
  }
  if (!plan_.precomputed) texture_ = layout::GradientTexture();
}

bool ShadingGradient::precomputed(const RenderSettings& settings) const {
  return plan_.precomputed && shadingActive(settings) && !settings.nearest;
}

void ShadingGradient::prepare(const RenderSettings& settings) {
  if (precomputed(settings) && !texture_.valid()) {
    texture_ = layout::GradientTexture::create(context_.ledger(), volume_);
  }
}

void ShadingGradient::addDefines(const RenderSettings& settings,
                                 std::vector<std::string>& defines) const {
  if (precomputed(settings)) defines.push_back("PRECOMPUTED_GRADIENT 1");
  if (valuesFromGradient(settings)) defines.push_back("GRADIENT_HOLDS_VALUES 1");
}

bool ShadingGradient::valuesFromGradient(const RenderSettings& settings) const {
  // The texture holds exactly what the layout's sampleVolume() reads: 8-bit
  // voxels stored as raw / 255 over the same grid.
  const layout::ValueMapping m = layout_.rawFromStored();
  return precomputed(settings) && texture_.holdsValues() && m.scale == 255.0 && m.offset == 0.0 &&
         texture_.gradients().dims == layout_.volumeDims();
}

void ShadingGradient::addParts(std::vector<gpu::ShaderPart>& parts) const {
  if (context_.caps().api == gpu::ApiLevel::Gles3) parts.push_back(layout::GradientTexture::glsl());
}

int ShadingGradient::bind(const gpu::Program& program, int unit,
                          const RenderSettings& settings) const {
  if (!precomputed(settings)) return 0;
  return texture_.bind(program, unit, layout_.rawFromStored().scale);
}

}  // namespace tessera::render
