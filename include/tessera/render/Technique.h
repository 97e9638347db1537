#pragma once
// The technique seam (DESIGN.md: volume source -> layout -> technique): one
// interface for every way of rendering the volume — ray casting, view- and
// axis-aligned slicing, and those to come — shared by the CLI, the hybrid
// compositor, the viewers and the benchmarks. A technique samples the volume
// through its layout's sampleVolume() (or keeps its own storage, as slice2d
// does) and renders into a colour texture of its own, which callers present,
// composite or read back. Techniques are made by name from the registry
// (render/TechniqueRegistry.h), which also says what each one needs of a
// device before it exists: the planner must leave room for it.
#include <cstdint>
#include <memory>
#include <string>

#include <glm/vec2.hpp>

#include "tessera/core/Camera.h"
#include "tessera/core/Error.h"
#include "tessera/core/Image.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/reference/AdaptiveSteps.h"
#include "tessera/reference/FusedVolume.h"
#include "tessera/reference/VoxelGradients.h"
#include "tessera/render/RowCosts.h"

namespace tessera::render {

// The user's knobs; each technique reads those that apply to it.
struct TechniqueOptions {
  glm::ivec2 imageSize{512, 512};  // the largest frame it will render (its target is reserved)
  int skipBlock = 8;               // raycast: empty-space block size in voxels (0 = off)
  int lutSize = 4096;              // raycast: TF table entries (256 or 4096)
  int slices = 0;                  // slice3d: over the diagonal; slice2d: per stack (0 = auto)
  std::string classify = "post";   // slice2d: pre, palette or post
  bool currentStackOnly = false;   // slice2d: only the stack being drawn on the GPU
  std::string gradient = "auto";   // raycast, shaded: auto, on-the-fly or precomputed
};

// What a technique needs of a device besides the volume's textures.
struct TechniqueRequirements {
  int textureUnits = 1;     // units it binds besides the layout's
  std::uint64_t bytes = 0;  // GPU bytes of its own (TF tables, grids, targets, buffers)
  // Non-empty: the technique stores the volume itself and says how ("its own
  // slice stacks"); no layout is planned or created for it.
  std::string ownStorage;
  std::string note;  // what the device made it give up ("empty-space skipping off: ...")
};

// What the last frames did, for the CLI's and the benchmarks' reports.
struct TechniqueReport {
  std::string note;  // "slice3d: 443 view-aligned slices, accumulation RGBA16F, ..."
  // A technique with its own storage: its name, a line about it and its bytes.
  std::string storage;
  std::string storageReason;
  std::uint64_t storageBytes = 0;
  double occupiedBlockFraction = 1.0;  // empty-space skipping: blocks the TF leaves occupied
  std::string gradient;  // shading: where the gradient comes from and why (empty: n/a)
};

// What the CPU reference needs to take the samples a technique's frames with
// some settings take (its twin, ReferenceRaycaster.h), and how it sampled.
struct SamplingTwin {
  const StepGrid* steps = nullptr;            // adaptive steps' block grid, when walked
  const VoxelGradients* gradients = nullptr;  // the precomputed gradient it shades from
  bool preintegrated = false;                 // segments classified by pre-integration
  double preintegrationBuildMs = 0.0;         // its table's last rebuild, CPU side
  double preintegrationUploadMs = 0.0;
};

class Technique {
 public:
  virtual ~Technique() = default;

  virtual std::string name() const = 0;
  virtual void setTransferFunction(const TransferFunction& tf) = 0;

  // Builds what frames with these settings need (programs, TF tables,
  // uploads), so that a timed frame measures rendering only. render() does
  // it too when something changed.
  virtual void prepare(const Camera& camera, const RenderSettings& settings) = 0;

  // Renders the volume, composited over settings.background, into a target
  // of about width x height pixels covering the view of a screen with aspect
  // ratio `viewAspect` (screen width / height; 0: width / height). Waits for
  // the GPU and returns the target's colour texture (row 0 at the bottom,
  // linear filtering), valid until the next call. The texture may have
  // another shape than asked (the slicers keep the screen's shape at the
  // same pixel count): callers use its size.
  virtual const gpu::Texture& render(const Camera& camera, const RenderSettings& settings,
                                     int width, int height, double viewAspect) = 0;
  // The last frame, top row first.
  virtual Image readImage() const = 0;

  // GPU bytes of its own resources, alive now.
  virtual std::uint64_t ownTextureBytes() const = 0;
  // Which pixels its frames cost at (RowCosts sizes progressive strips by it).
  virtual Footprint footprint() const { return Footprint::VolumeBox; }
  virtual TechniqueReport report() const { return {}; }
  // A technique that honours RenderSettings::sampling says what its frames
  // with `settings` did; the default: every sample, post-classified.
  virtual SamplingTwin samplingTwin(const RenderSettings& settings) const {
    (void)settings;
    return {};
  }

  // A second volume mixed into the samples (docs/fusion.md); null: none.
  // Techniques that cannot fuse refuse one with an InputError.
  virtual void setFusion(std::shared_ptr<const FusedVolume> fused) {
    if (fused) throw InputError(name() + " cannot show a fused volume (--overlay): use raycast");
  }

  // A width x height frame for a screen of that shape, read back.
  Image renderImage(const Camera& camera, const RenderSettings& settings, int width, int height) {
    render(camera, settings, width, height, 0.0);
    return readImage();
  }
};

}  // namespace tessera::render
