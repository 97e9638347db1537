#pragma once
// The layout <-> technique seam (Noguera & Jiménez 2012's texture coordinate
// adapter): a Layout owns how a volume lives in textures and provides the
// GLSL function every technique samples through,
//
//   float sampleVolume(vec3 p);   // p in [0,1]^3, voxel centres at (i+0.5)/dims
//
// returning a "stored value" s that relates to raw voxel values by the affine
// map rawFromStored(). Techniques never see textures, only that function.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/Program.h"
#include "tessera/layout/ValueBlocks.h"
#include "tessera/reference/Reconstruction.h"

namespace tessera::layout {

// raw = scale * stored + offset
struct ValueMapping {
  double scale = 1.0;
  double offset = 0.0;
};

// One texture a layout will allocate.
struct PlannedTexture {
  std::string label;
  glm::ivec3 size{0};  // z = 1 for 2D textures
  bool is3D = false;
  std::string format;  // "R8", "R16", "R16F", "RGBA8", ...
  std::uint64_t bytes = 0;
};

class StreamingLayout;

// The field sampleVolume() reconstructs, as the CPU reference renders it:
// `field` over the box of `box` (extent, spacing, window). Empty (both
// null): the trilinear (or, with RenderSettings::nearest, nearest) field of
// the voxels the layout was made from.
struct ReferenceField {
  const Volume* box = nullptr;
  std::shared_ptr<const Reconstruction> field;
  bool ownField() const { return field != nullptr; }
};

struct LayoutPlan {
  std::string layout;  // "texture3d", "mosaic", "packed-mosaic"
  bool fits = false;   // false: `reason` says which limit it breaks
  std::vector<PlannedTexture> textures;
  std::uint64_t totalBytes = 0;
  std::string reason;  // one line a human can read
};

class Layout {
 public:
  virtual ~Layout() = default;
  virtual std::string name() const = 0;
  virtual const LayoutPlan& plan() const = 0;
  // GLSL for the API level the layout was created for (GLSL ES 1.00 for
  // gles2: texture2D via the preamble's TEX2D macro, no integer tricks;
  // GLSL ES 3.00 for gles3) defining sampleVolume() and the samplers and
  // uniforms it needs. Uniform names are prefixed "u_layout".
  virtual gpu::ShaderPart glsl() const = 0;
  // Every GLSL file of the layout's seam in order (glsl() first; a layout
  // with generated parts, e.g. fcc, adds them).
  virtual std::vector<gpu::ShaderPart> glslParts() const { return {glsl()}; }
  // Binds the layout's textures to units firstUnit.. and sets its uniforms
  // in `program` (which must be in use). Returns the number of units used.
  virtual int bind(const gpu::Program& program, int firstUnit) const = 0;
  virtual ValueMapping rawFromStored() const = 0;
  // Texture units bind() uses.
  virtual int textureUnits() const = 0;
  virtual glm::ivec3 volumeDims() const = 0;
  // Bytes of GPU memory the layout's textures occupy (from the ledger).
  virtual std::uint64_t textureBytes() const = 0;

  // How far, in voxels, the reconstruction behind sampleVolume() reaches
  // (trilinear, every layout today: 1).
  virtual int supportVoxels() const { return 1; }
  // Min/max of raw values per block for empty-space skipping, covering every
  // sample sampleVolume() can return inside each block. In-core layouts
  // compute it from the volume they were made from; a layout without one
  // (bricks streamed from disk) overrides it with its own metadata.
  virtual ValueBlocks valueBlocks(int blockSize) const;
  // Whether the layout's GLSL offers the brick walk (LAYOUT_BRICK_WALK,
  // render/raycast.frag.glsl): layoutWalkCellsPerUnit(), the cells of its
  // grid per texture-space unit; layoutEnterCell(p), read once when a ray
  // enters the cell holding p, returning that cell; layoutCellTransparent(),
  // 1.0 when that cell is known to be transparent (composite crosses it in
  // one step); sampleVolumeInCell(p) for the samples inside it. Layouts that look something up per
  // sample (bricks: the page table) read it once per cell that way.
  virtual bool walksBricks() const { return false; }
  // Changes whenever what sampleVolume() returns may have changed (a
  // streamed layout's page table), so techniques rebuild their value blocks.
  virtual std::uint64_t contentVersion() const { return 0; }

  // Non-null for a layout that streams its volume (bricks): the front end
  // drives its per-frame refinement through it.
  virtual StreamingLayout* streaming() { return nullptr; }
  virtual const StreamingLayout* streaming() const { return nullptr; }
  // True for a layout whose seam defines CHANNELS (several channels,
  // docs/channels.md): techniques whose MIP needs more than one value per
  // sample (slice3d's per channel maxima) ask this.
  virtual bool drawsChannels() const { return false; }
  // What the CPU reference renders as this layout's twin (fcc: the box
  // spline over its lattice); default: the voxels it was made from.
  virtual ReferenceField referenceField() const { return {}; }

  // The seam's GLSL as a technique includes it: the layout's glslParts() and then
  // the shared gradient part (layout/gradient.glsl: sampleVolumeGradient() by
  // central differences through sampleVolume(), unless the layout defines
  // LAYOUT_HAS_GRADIENT and its own). Use with bindSeam().
  std::vector<gpu::ShaderPart> seamParts() const;
  // bind() plus the seam's own uniforms; returns the units used.
  int bindSeam(const gpu::Program& program, int firstUnit) const;

 protected:
  // The in-core volume the layout was made from (it must outlive the layout).
  const Volume* voxels_ = nullptr;
};

}  // namespace tessera::layout
