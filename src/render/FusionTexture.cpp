#include "tessera/render/FusionTexture.h"

#include <algorithm>
#include <vector>

#include "tessera/core/Error.h"

namespace tessera::render {

namespace {

// Labels: one entry per label value (LabelTable.h); another modality: the
// ray caster's fine table.
int tableEntries(const FusedVolume& f) {
  return f.labels ? 256 : 4096;
}

}  // namespace

void FusionTexture::checkDevice(const gpu::DeviceLimits& limits, const FusedVolume& fused) {
  const glm::ivec3 d = fused.volume->dims();
  if (limits.max3DTextureSize <= 0) {
    throw InputError("a fused volume (--overlay) needs 3D textures: an ES 3 profile (" +
                     limits.profile + " has none)");
  }
  if (std::max({d.x, d.y, d.z}) > limits.max3DTextureSize) {
    throw InputError("the fused volume " + std::to_string(d.x) + "x" + std::to_string(d.y) + "x" +
                     std::to_string(d.z) + " exceeds " + limits.profile + "'s 3D textures of " +
                     std::to_string(limits.max3DTextureSize));
  }
}

void FusionTexture::set(std::shared_ptr<const FusedVolume> fused) {
  fused_ = std::move(fused);
  if (!fused_) return;
  const Volume& v = *fused_->volume;
  if (!v.hasData()) throw InputError("the fused volume has no voxels in memory");
  if (context_.caps().api != gpu::ApiLevel::Gles3) {
    throw InputError(
        "a fused volume (--overlay) needs 3D textures: an ES 3 profile (this one is ES 2)");
  }
  if (uploaded_ != &v) {
    // Normalised to the value range in half floats: 11 bits of precision
    // for any value range, filterable on every ES 3 device.
    const ValueRange r = v.valueRange();
    const double rw = r.width() > 0.0 ? r.width() : 1.0;
    std::vector<float> texels(v.voxelCount());
    for (std::size_t i = 0; i < texels.size(); ++i) {
      texels[i] = static_cast<float>((v.finiteValueAtIndex(i) - r.min) / rw);
    }
    const glm::ivec3 d = v.dims();
    texture_ = gpu::Texture();
    texture_ = gpu::Texture::create3D(context_.ledger(), "fused volume", gpu::TexelFormat::R16F,
                                      d.x, d.y, d.z, texels.data());
    texture_.setFilter(fused_->labels ? gpu::Filter::Nearest : gpu::Filter::Linear);
    uploaded_ = &v;
  }
  std::string key = fused_->tf.toJson();
  key += fused_->labels ? "|labels" : "|values";
  if (key != tableKey_) {
    // Opacity uncorrected (the step's correction is fusion.glsl's).
    table_.upload(context_,
                  fused_->tf.bake(tableEntries(*fused_), fused_->tf.opacityUnitLength, 1.0),
                  "fused transfer function");
    tableKey_ = key;
  }
}

void FusionTexture::addDefines(std::vector<std::string>& defines) const {
  if (!fused_) return;
  defines.push_back("FUSION 1");
  if (fused_->labels) defines.push_back("FUSION_LABELS 1");
}

void FusionTexture::addParts(std::vector<gpu::ShaderPart>& parts) const {
  if (fused_) parts.push_back(gpu::embeddedShaderPart("render/fusion.glsl"));
}

int FusionTexture::bind(const gpu::Program& program, int unit, const Volume& anatomy,
                        double ds) const {
  if (!fused_) return 0;
  const FusedVolume& f = *fused_;
  const ValueRange r = f.volume->valueRange();
  const double rw = r.width() > 0.0 ? r.width() : 1.0;
  const double ww = f.window.width();
  texture_.bind(unit);
  program.set("u_fused", unit);
  table_.texture().bind(unit + 1);
  program.set("u_fusedTf", unit + 1);
  program.set("u_fusedTfSize", static_cast<float>(table_.entries()));
  program.set("u_fusedFromAnatomy", glm::mat4(fusedFromAnatomy(anatomy, *f.volume)));
  program.set("u_fusedScale", static_cast<float>(rw / ww));
  program.set("u_fusedBias", static_cast<float>((r.min - f.window.min) / ww));
  program.set("u_fusedOpacity", static_cast<float>(f.opacity));
  program.set("u_fusedStepRatio", static_cast<float>(ds / f.tf.opacityUnitLength));
  program.set("u_fusedDims", glm::vec3(f.volume->dims()));
  return 2;
}

}  // namespace tessera::render
