#pragma once
// View-aligned texture slicing with static proxy geometry (Noguera et al.
// 2012, GRAPP, section 3.2, after Van Gelder & Kim 1996): N quads over a
// cube whose side is the volume's diagonal are built once into a VBO; per
// frame only matrices change — the cube is turned to face the viewer and the
// texture coordinates are rotated with it, so the slices stay perpendicular
// to the view direction. Fragments outside the volume get alpha 0 (no
// discard). Samples go through the layout's sampleVolume(), so every layout
// works, in ES 2.0 and ES 3.0 contexts alike.
//
// Opacity: the TF table is baked for the slice spacing ds = diagonal / N; a
// perspective ray crosses consecutive planes ds / cos(theta) apart, so each
// fragment corrects its opacity once more by that ratio (DESIGN.md,
// Rendering semantics). No early termination (blending has no way to stop).
// Slabs: where the accumulation target is RGBA8 (a device without float
// render targets) every blend rounds to 8 bits, and a thin plane's
// contribution is a fraction of a level. There each quad stands for
// kRgba8SlabSamples consecutive planes: its fragment samples the planes
// where its view ray crosses them, composites them front to back in the
// shader and blends once, dithered by half a level (slice3d.frag.glsl). The
// samples are the N planes' own; only the roundings drop K-fold
// (docs/rendering.md, docs/channels.md for the measurements).
// Over a layout that draws channels (docs/channels.md) each fragment combines
// them as the ray caster's samples do; their MIP keeps per channel maxima in
// two targets and colours them in a resolve pass.
// The "slice3d" technique of the registry (render/TechniqueRegistry.h).
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
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
#include "tessera/render/ShadingGradient.h"
#include "tessera/render/SliceAccumulator.h"
#include "tessera/render/Technique.h"
#include "tessera/render/TechniqueRegistry.h"

namespace tessera::render {

class Slice3DRenderer final : public Technique {
 public:
  // `volume` and `layout` must outlive the renderer.
  // `halfFloatAccumulation` as SliceAccumulator's (the registry passes the
  // device limits' halfFloatRenderTargets).
  Slice3DRenderer(gpu::GlContext& context, const Volume& volume, const layout::Layout& layout,
                  std::optional<bool> halfFloatAccumulation = std::nullopt);

  void setTransferFunction(const TransferFunction& tf) override;
  // Number of slices over the cube's side; 0 (the default) derives it from
  // RenderSettings::stepVoxels: N = ceil(diagonal / ds).
  void setSliceCount(int slices);
  // Samples each proxy slice composites along its view ray before its one
  // blend (1..kMaxSlabSamples); 0 (the default): kRgba8SlabSamples where the
  // accumulation target is RGBA8, else 1. MIP always takes 1.
  void setSlabSamples(int samples);
  int slabSamplesFor(const RenderSettings& settings) const;
  // Whether slabs dither their 8-bit rounding (slice3d.frag.glsl).
  bool ditherFor(const RenderSettings& settings) const;
  // Planes a frame with these settings samples (1..kMaxSlices).
  int sliceCountFor(const RenderSettings& settings) const;
  // World distance between slices for these settings.
  double sliceSpacingFor(const RenderSettings& settings) const;

  // Where shaded frames take the gradient (render/ShadingGradient.h).
  void setGradient(layout::GradientWish wish) { gradient_.setWish(wish); }
  const layout::GradientTexture& gradientTexture() const { return gradient_.texture(); }
  bool precomputedGradient(const RenderSettings& settings) const {
    return gradient_.precomputed(settings);
  }

  void prepare(const RenderSettings& settings);
  void renderFrame(const Camera& camera, const RenderSettings& settings, int width, int height);
  Image readImage() const override { return accumulator_.readImage(); }
  const gpu::Texture& colorTexture() const { return accumulator_.colorTexture(); }
  Image render(const Camera& camera, const RenderSettings& settings, int width, int height) {
    renderFrame(camera, settings, width, height);
    return readImage();
  }

  // The proxy geometry: how often it was built, and its buffer. A camera
  // change never rebuilds it; a new slice count does.
  std::uint64_t geometryBuilds() const { return geometryBuilds_; }
  unsigned vertexBufferId() const { return vertices_.id(); }
  std::uint64_t vertexBufferBytes() const { return vertices_.bytes(); }

  std::vector<gpu::ShaderPart> vertexParts() const;
  std::vector<gpu::ShaderPart> fragmentParts(const RenderSettings& settings) const;
  // The resolve pass of channel maxima (a layout that drawsChannels(), max).
  std::vector<gpu::ShaderPart> channelResolveParts() const;
  std::string accumulationFormat() const { return accumulator_.accumulationFormat(); }
  std::uint64_t ownTextureBytes() const override;

  static constexpr int kMaxSlices = 8192;
  static constexpr int kMaxSlabSamples = 64;
  static constexpr int kRgba8SlabSamples = 32;
  static constexpr int kOwnTextureUnits = 1;  // the TF table

  // The Technique interface. The target keeps the screen's shape (see
  // sliceTargetSize): the projection always fills it.
  std::string name() const override { return "slice3d"; }
  // Its static proxy cube covers the volume's bounding sphere at any angle.
  Footprint footprint() const override { return Footprint::ViewCube; }
  void prepare(const Camera& camera, const RenderSettings& settings) override;
  const gpu::Texture& render(const Camera& camera, const RenderSettings& settings, int width,
                             int height, double viewAspect) override;
  TechniqueReport report() const override;

  // The registry's entry: one unit for the TF table; the bytes of a frame
  // target and the table.
  // As the registry makes it (TechniqueRegistry::create), for callers that
  // need its own interface (the slicing benchmark).
  static std::unique_ptr<Slice3DRenderer> create(const TechniqueSetup& setup);
  static TechniqueEntry registration();
  static TechniqueRequirements requirements(const gpu::DeviceLimits& limits, glm::ivec3 volumeDims,
                                            const TechniqueOptions& options);

 private:
  const gpu::Program& programFor(const RenderSettings& settings);
  void buildGeometry(int slices, int slabSamples);
  void updateLookup(const RenderSettings& settings, double spacing);
  void drawChannelMaxima(const gpu::Program& slices, const RenderSettings& settings);
  const gpu::Program& channelResolveProgram();

  gpu::GlContext& context_;
  const Volume& volume_;
  const layout::Layout& layout_;
  TransferFunction tf_;
  int requestedSlices_ = 0;
  int requestedSlabSamples_ = 0;
  int builtSlices_ = 0;
  int builtSlabSamples_ = 0;
  int builtSlabs_ = 0;
  std::uint64_t geometryBuilds_ = 0;
  gpu::Buffer vertices_;
  gpu::LookupTexture lut_;
  std::string lookupKey_;
  SliceAccumulator accumulator_;
  ShadingGradient gradient_;
  gpu::ProgramCache programs_;
};

}  // namespace tessera::render
