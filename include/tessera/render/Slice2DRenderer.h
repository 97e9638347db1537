#pragma once
// Axis-aligned texture slicing (Moser & Weiskopf 2008, section 4): three
// stacks of 2D slices in atlases; each frame draws the stack most
// perpendicular to the view front to back (render/SliceAccumulator.h), one
// draw call per atlas. Needs no 3D textures and no layout: 2D textures only,
// in ES 2.0 and ES 3.0 contexts.
//
// Classification, and what a TF change costs:
//  - Pre: the TF applied on the CPU into premultiplied RGBA8 slices
//    (hardware-filtered after classification); a TF change re-creates and
//    re-uploads every resident slice.
//  - Palette: 8-bit index slices + a 256-entry palette, the shader doing
//    what GL_PALETTE8_RGBA8_OES did in hardware — look up the four nearest
//    indices and filter the classified colours (pre-classification
//    semantics); a TF change uploads the palette only.
//  - Post: 8-bit index slices filtered as scalars, then the TF table lookup
//    (the ray caster's semantics); a TF change uploads the table only.
// Indices are the value window quantised to 8 bits (exact for u8 volumes).
//
// The "slice2d" technique of the registry (render/TechniqueRegistry.h); it
// keeps its own slice stacks, so no layout is planned for it.
//
// Opacity: tables are baked for ds0 = the smallest voxel spacing; a
// fragment stands for the distance its ray travels between drawn planes,
// (stack spacing * stride) / |cos(angle to the stack axis)|, and corrects
// its opacity by that ratio.
//
// Channels (docs/channels.md, "Techniques"): over a layout that
// drawsChannels() (Slice2DOptions::channels; the registry passes the
// session's channel layout) the same stack planes sample the layout's
// sampleChannels() at their voxel planes instead of stacks of their own —
// the layout holds four channels a texel once, where three stacks per four
// channels would hold them three times; on ES 2 the layout is itself 2D (a
// mosaic of z-slices). As for 2D-texture slicing with intermediate slices
// (Rezk-Salama et al. 2000: trilinear interpolation between adjacent 2D
// slices) the planes follow the step, N = ceil(extent / ds) along the stack
// axis (--slices N: N), so that rays are sampled as densely as the ray
// caster's. Post-classified only; the additive fragment is
// classifiedChannels(), the max mode draws the stack twice (channels 0-3,
// then 4-5 and the hit flag) and resolves as slice3d does.
// Slabs (channels, additive): where the accumulation target is RGBA8 (no
// float render targets) every blend rounds to 8 bits and a thin plane's
// contribution is a fraction of a level. There, as slice3d does, each quad
// stands for kRgba8SlabPlanes consecutive planes of the stack: its fragment
// samples the planes where its view ray crosses them, composites them front
// to back in the shader and blends once, dithered by half a level
// (slice2d_channels.frag.glsl). The samples are the N planes' own; only the
// roundings drop K-fold. A slab's quad lies on its first plane, widened by
// 2 (K - 1) plane spacings on each side so that rays up to 63 degrees off
// the stack axis in either tile direction still meet its farther planes
// (docs/channels.md for the measurements). The single-volume stacks keep
// one plane a blend: their planes are atlas tiles, possibly in different
// atlases, which a fragment cannot reach from one draw.
#include <array>
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
#include "tessera/render/SliceAccumulator.h"
#include "tessera/render/SliceStacks.h"
#include "tessera/render/Technique.h"
#include "tessera/render/TechniqueRegistry.h"

namespace tessera::render {

enum class SliceClassification { Pre, Palette, Post };
const char* sliceClassificationName(SliceClassification c);             // "pre", "palette", "post"
SliceClassification parseSliceClassification(const std::string& name);  // InputError if unknown

struct Slice2DOptions {
  SliceClassification classification = SliceClassification::Post;
  // Keep only the stack being drawn on the GPU (a third of the memory);
  // a change of stack axis re-creates it (the hitch stackUploadMs() reports).
  bool currentStackOnly = false;
  bool powerOfTwoAtlases = false;
  int maxTextureSize = 0;  // 0: the context's limit
  // Half-float accumulation (SliceAccumulator): nullopt where the context
  // renders to half floats; the device's limits decide through the registry.
  std::optional<bool> halfFloatAccumulation = std::nullopt;
  // Non-null: draw these channels (a layout that drawsChannels(), which
  // must outlive the renderer) instead of stacks of the volume's own.
  const layout::Layout* channels = nullptr;
};

class Slice2DRenderer final : public Technique {
 public:
  // `volume` must outlive the renderer.
  Slice2DRenderer(gpu::GlContext& context, const Volume& volume, const Slice2DOptions& options);
  ~Slice2DRenderer() override;

  void setTransferFunction(const TransferFunction& tf) override;
  // Slices drawn per frame: 0 (the default) draws every slice of the stack;
  // fewer picks evenly spaced ones (the opacity corrected for the gap).
  void setSliceCount(int slices);
  // Channel planes each quad composites before its one blend
  // (1..kMaxSlabPlanes); 0 (the default): kRgba8SlabPlanes where the
  // accumulation target is RGBA8, else 1. MIP and the single-volume stacks
  // always take 1.
  void setSlabPlanes(int planes);
  int slabPlanesFor(const RenderSettings& settings) const;
  static constexpr int kMaxSlabPlanes = 64;
  static constexpr int kRgba8SlabPlanes = 32;

  // The stack for a view: the axis along which the view direction is largest.
  static int stackAxisFor(const Camera& camera);

  void prepare(const Camera& camera, const RenderSettings& settings) override;
  void renderFrame(const Camera& camera, const RenderSettings& settings, int width, int height);
  Image readImage() const override { return accumulator_.readImage(); }
  const gpu::Texture& colorTexture() const { return accumulator_.colorTexture(); }
  Image render(const Camera& camera, const RenderSettings& settings, int width, int height) {
    renderFrame(camera, settings, width, height);
    return readImage();
  }

  // Re-creates every resident stack texture from the host copy, as a
  // paletted texture format that fixes its palette at creation needs on
  // every TF change (for the TF-update benchmark).
  void recreateStackTextures();

  const SliceAtlasPlan& atlasPlan(int axis) const { return plans_[axis]; }
  int lastStackAxis() const { return lastAxis_; }
  int slicesDrawn() const { return lastSlicesDrawn_; }
  // How many stack (re)creations and TF re-classifications happened, and
  // the time of the last one (host work + upload, ms).
  std::uint64_t stackUploads() const { return stackUploads_; }
  double lastStackUploadMs() const { return lastStackUploadMs_; }
  std::uint64_t classificationUpdates() const { return classificationUpdates_; }
  std::uint64_t stackTextureBytes() const;
  std::uint64_t ownTextureBytes() const override;
  const Slice2DOptions& options() const { return options_; }
  std::string accumulationFormat() const { return accumulator_.accumulationFormat(); }

  std::vector<gpu::ShaderPart> vertexParts() const;
  // Over channels (Slice2DOptions::channels), the channel fragment's.
  std::vector<gpu::ShaderPart> fragmentParts(const RenderSettings& settings) const;
  // The resolve pass of channel maxima (channels, max mode).
  std::vector<gpu::ShaderPart> channelResolveParts() const;

  // The Technique interface. The target keeps the screen's shape (see
  // sliceTargetSize): the projection always fills it.
  std::string name() const override { return "slice2d"; }
  const gpu::Texture& render(const Camera& camera, const RenderSettings& settings, int width,
                             int height, double viewAspect) override;
  TechniqueReport report() const override;

  // The registry's entry: its own stacks (no layout), the atlas and TF units.
  // As the registry makes it (TechniqueRegistry::create), for callers that
  // need its own interface (the slicing benchmark).
  static std::unique_ptr<Slice2DRenderer> create(const TechniqueSetup& setup);
  static TechniqueEntry registration();
  static TechniqueRequirements requirements(const gpu::DeviceLimits& limits, glm::ivec3 volumeDims,
                                            const TechniqueOptions& options);

 private:
  struct DrawRange {
    int atlas;
    int firstIndex;
    int count;
  };
  struct DrawList {
    gpu::Buffer indices;
    std::vector<DrawRange> ranges;
    double gapRatio = 1.0;  // drawn planes are gapRatio * stack spacing apart
    gpu::Buffer vertices;   // channel planes: their own quads (else the stack's)
  };

  const gpu::Program& programFor(const RenderSettings& settings);
  std::vector<gpu::ShaderPart> channelFragmentParts(const RenderSettings& settings) const;
  const gpu::Program& channelResolveProgram();
  const DrawList& channelPlanes(int axis, bool descending, int planes, int slabPlanes);
  int channelPlaneCount(const RenderSettings& settings, int axis) const;
  void drawStack(const gpu::Program& prog, int axis, const DrawList& list);
  void drawChannelMaxima(const gpu::Program& prog, int axis, const DrawList& list,
                         const RenderSettings& settings);
  void buildGeometry(int axis);
  const DrawList& drawList(int axis, bool descending, int slices);
  void uploadStack(int axis);
  void updateClassification(const RenderSettings& settings);
  double baseDistance() const;

  gpu::GlContext& context_;
  const Volume& volume_;
  Slice2DOptions options_;
  std::optional<SliceStacks> stacks_;  // none for channels
  std::array<SliceAtlasPlan, 3> plans_;
  std::array<std::vector<gpu::Texture>, 3> atlases_;
  std::array<gpu::Buffer, 3> vertices_;
  std::map<std::string, DrawList> drawLists_;
  TransferFunction tf_;
  int requestedSlices_ = 0;
  int requestedSlabPlanes_ = 0;
  int lastSlabPlanes_ = 1;
  std::string classificationKey_;
  std::vector<std::uint8_t> palette8_;  // pre: premultiplied RGBA8, 256 entries
  gpu::LookupTexture table_;            // palette or post-classification LUT
  SliceAccumulator accumulator_;
  gpu::ProgramCache programs_;
  bool shadedStacks_ = false;  // the stacks carry neighbours for shading
  int lastAxis_ = -1;
  int lastSlicesDrawn_ = 0;
  std::uint64_t stackUploads_ = 0;
  double lastStackUploadMs_ = 0.0;
  std::uint64_t classificationUpdates_ = 0;
};

}  // namespace tessera::render
