#pragma once
// The single-pass GPU ray caster, in OpenGL ES 2.0 and 3.0 contexts alike.
// Works on any Layout (it only calls sampleVolume()), with composite and MIP
// modes, early ray termination, jitter and empty-space skipping over a block
// min/max grid, pre-integrated classification and adaptive steps over that
// grid (docs/sampling.md). Besides the layout's units it uses two: the TF (or
// the pre-integration table) and the grid.
// The "raycast" technique of the registry (render/TechniqueRegistry.h).
#include <glm/vec2.hpp>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "tessera/core/Camera.h"
#include "tessera/core/Image.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/core/Volume.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/LookupTexture.h"
#include "tessera/gpu/Program.h"
#include "tessera/gpu/ProgramCache.h"
#include "tessera/layout/Layout.h"
#include "tessera/layout/ValueBlocks.h"
#include "tessera/reference/AdaptiveSteps.h"
#include "tessera/render/FusionTexture.h"
#include "tessera/render/PreIntegrationTable.h"
#include "tessera/render/ShadingGradient.h"
#include "tessera/render/Technique.h"
#include "tessera/render/TechniqueRegistry.h"

namespace tessera::render {

class Raycaster final : public Technique {
 public:
  // `volume` and `layout` must outlive the ray caster (the volume supplies
  // the value window and the block min/max grid).
  Raycaster(gpu::GlContext& context, const Volume& volume, const layout::Layout& layout);
  ~Raycaster() override;

  void setTransferFunction(const TransferFunction& tf) override;
  // A fused volume (render/FusionTexture.h): composite frames only; empty-space
  // skipping is off while one is shown (the anatomy's empty blocks may hold it).
  void setFusion(std::shared_ptr<const FusedVolume> fused) override {
    fusion_.set(std::move(fused));
  }
  // Block size of the empty-space grid in voxels; 0 disables skipping.
  void setSkipBlockSize(int voxels);
  // TF lookup-table entries (256 or 4096).
  void setLutSize(int entries);
  // Entries per axis of the pre-integration table (default 256).
  void setPreintegrationEntries(int entries);
  // The pre-integration table in RGBA8 even where half floats filter.
  void setPreintegrationEightBit(bool eightBit) {
    preint_.setEightBit(eightBit);
    lookupKey_.clear();
  }

  // Where shaded frames take the gradient (layout/GradientTexture.h): the
  // plan's choice by default. Throws InputError for Precomputed where it
  // cannot be had.
  void setGradient(layout::GradientWish wish) { gradient_.setWish(wish); }
  const layout::GradientPlan& gradientPlan() const { return gradient_.plan(); }
  // The precomputed gradient the last shaded frame used; not valid() when it
  // took central differences on the fly.
  const layout::GradientTexture& gradientTexture() const { return gradient_.texture(); }
  // Whether frames with these settings shade from the precomputed gradient.
  bool precomputedGradient(const RenderSettings& settings) const {
    return gradient_.precomputed(settings);
  }

  // Compiles the program and builds the lookup tables the settings need, so
  // that a timed frame measures rendering only.
  void prepare(const RenderSettings& settings);

  // Renders into the internal framebuffer and waits for it (glFinish).
  void renderFrame(const Camera& camera, const RenderSettings& settings, int width, int height);
  // Reads the last frame (top row first).
  Image readImage() const override;
  // The last frame's colour texture (row 0 at the bottom), valid until the
  // next renderFrame(): what a compositor samples without a read-back.
  const gpu::Texture& colorTexture() const { return target_.color(); }
  // Aspect ratio of the view the rays cover; 0 (the default) means the
  // frame's width / height. The hybrid compositor renders a fixed-size target
  // (e.g. 128x128) for a 480x640 screen and stretches it when upscaling.
  void setViewAspect(double aspect) { viewAspect_ = aspect; }
  Image render(const Camera& camera, const RenderSettings& settings, int width, int height) {
    renderFrame(camera, settings, width, height);
    return readImage();
  }

  // Fraction of empty-space blocks the current TF and window leave
  // occupied (1 when skipping is off); valid after prepare()/renderFrame().
  double occupiedBlockFraction() const { return occupiedFraction_; }
  // The block grid as the last frame walked it (codes: 0 empty, else the
  // step allowance, AdaptiveSteps.h), for the CPU reference to take the same
  // samples; not valid() without a grid.
  const StepGrid& stepGrid() const { return stepGrid_; }
  // The pre-integration table (built when a frame pre-integrates).
  const PreIntegrationTable& preintegrationTable() const { return preint_; }
  SamplingTwin samplingTwin(const RenderSettings& settings) const override;

  static constexpr int kOwnTextureUnits = 2;

  // The shader parts of the program these settings need (for offline
  // validation of the GLSL, e.g. with glslangValidator).
  std::vector<gpu::ShaderPart> vertexParts() const;
  std::vector<gpu::ShaderPart> fragmentParts(const RenderSettings& settings) const;

  // GPU memory of this ray caster's own resources (TF, block grid, target).
  std::uint64_t ownTextureBytes() const override;

  // The Technique interface.
  std::string name() const override { return "raycast"; }
  void prepare(const Camera& camera, const RenderSettings& settings) override;
  const gpu::Texture& render(const Camera& camera, const RenderSettings& settings, int width,
                             int height, double viewAspect) override;
  TechniqueReport report() const override;

  // The registry's entry: a TF table and the empty-space grid (two units, or
  // one with skipping off where the device has fewer than three), the
  // render target and the grid's bytes.
  static TechniqueEntry registration();
  static TechniqueRequirements requirements(const gpu::DeviceLimits& limits, glm::ivec3 volumeDims,
                                            const TechniqueOptions& options);
  // The block size a device allows for the one asked: 0 when it has too few
  // texture units for the grid (one must stay for the volume).
  static int skipBlockFor(const gpu::DeviceLimits& limits, int requested);

 private:
  const gpu::Program& programFor(const RenderSettings& settings);
  std::vector<std::string> definesFor(const RenderSettings& settings) const;
  void updateLookup(const RenderSettings& settings, double sampleDistance);
  // Whether frames with these settings read the table's opacity as log2 of a
  // base step's transmittance (raycast.frag.glsl, LOG_TRANSMITTANCE).
  bool logTransmittance(const RenderSettings& settings) const;
  void uploadLut();
  void refreshValueBlocks();
  void updateTables(const RenderSettings& settings, double sampleDistance, bool pre, bool logT);
  void classifyBlocks(const RenderSettings& settings, double sampleDistance, bool pre,
                      bool adaptive);
  void uploadBlocks(const std::vector<std::uint8_t>& cells);
  void useTarget(int width, int height);

  gpu::GlContext& context_;
  const Volume& volume_;
  const layout::Layout& layout_;
  TransferFunction tf_;
  int lutSize_ = 4096;
  int blockSize_ = 8;
  layout::ValueBlocks blocks_;
  std::uint64_t blocksVersion_ = 0;  // layout_.contentVersion() the blocks were made for
  std::vector<float> lutValues_;     // the baked TF, 4 floats per entry
  gpu::LookupTexture lut_;
  PreIntegrationTable preint_;
  int preintEntries_ = PreIntegrationTable::kDefaultEntries;
  StepGrid stepGrid_;
  ShadingGradient gradient_;
  FusionTexture fusion_;
  gpu::Texture blockTexture_;
  gpu::Framebuffer target_;
  // Targets held beside target_, the most recently used first: a full
  // frame's and previews' (useTarget()).
  std::vector<gpu::Framebuffer> spareTargets_;
  gpu::FullscreenTriangle triangle_;
  gpu::ProgramCache programs_;
  // What the LUT/block texture were built for, to rebuild only on change.
  std::string lookupKey_;
  // The lookupKey_ the blocks were classified for (cleared when the layout's
  // content changed them).
  std::string blocksKey_;
  double occupiedFraction_ = 1.0;
  double viewAspect_ = 0.0;
  int blockTilesX_ = 1;
  glm::ivec2 blockTexSize_{0};
};

}  // namespace tessera::render
