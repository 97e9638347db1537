#pragma once
// The GPU side of a fused volume (reference/FusedVolume.h, docs/fusion.md):
// its voxels in a 3D texture (R16F, normalised to the volume's value range;
// ES 3 profiles only), its table, and the shader part (render/fusion.glsl)
// and uniforms a ray caster adds to mix it into its samples.
#include <memory>
#include <string>
#include <vector>

#include "tessera/core/Volume.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/LookupTexture.h"
#include "tessera/gpu/Program.h"
#include "tessera/reference/FusedVolume.h"

namespace tessera::render {

class FusionTexture {
 public:
  explicit FusionTexture(gpu::GlContext& context) : context_(context) {}

  // InputError unless the device's profile holds the fused volume in a 3D
  // texture (ES 3 profiles; a context may offer more than its profile).
  static void checkDevice(const gpu::DeviceLimits& limits, const FusedVolume& fused);

  // Uploads the fused volume (again only when it is another one) and its
  // table; null turns fusion off. InputError on an ES 2 context (no 3D
  // textures) and for an empty volume.
  void set(std::shared_ptr<const FusedVolume> fused);
  bool active() const { return fused_ != nullptr; }
  const FusedVolume* fused() const { return fused_.get(); }

  // FUSION (and FUSION_LABELS) when active.
  void addDefines(std::vector<std::string>& defines) const;
  // render/fusion.glsl when active (before render/sample.glsl).
  void addParts(std::vector<gpu::ShaderPart>& parts) const;
  // Binds the volume and table from `unit` for a frame of `anatomy` at sample
  // distance ds; the units it used (0 when inactive).
  int bind(const gpu::Program& program, int unit, const Volume& anatomy, double ds) const;
  std::uint64_t bytes() const { return texture_.bytes() + table_.bytes(); }

 private:
  gpu::GlContext& context_;
  std::shared_ptr<const FusedVolume> fused_;
  const Volume* uploaded_ = nullptr;  // the volume texture_ holds
  std::string tableKey_;
  gpu::Texture texture_;
  gpu::LookupTexture table_;
};

}  // namespace tessera::render
