#pragma once
// The volume as a mosaic: every z-slice is a W x H tile of ONE single-channel
// 2D texture (Noguera et al. 2012, "Volume rendering strategies on mobile
// devices", section 3.1, after Congote et al. 2011), for devices without 3D
// textures (ES 2.0 / WebGL 1). Trilinear reconstruction is two hardware
// bilinear fetches, one in each of the two slices around p.z, and a mix.
//
// Storage: u8 is exact (R8 on gles3, LUMINANCE on gles2). Other types are
// normalised over the volume's value range: into 16 bits on gles3 (R16 with
// EXT_texture_norm16, else R16F, as in Texture3DLayout), but into 8 bits on
// gles2, which has no single-channel 16-bit texture format that filters
// everywhere — a loss of up to half a step of (max - min) / 255 per voxel.
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/vec2.hpp>

#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/MemoryLedger.h"
#include "tessera/layout/Layout.h"
#include "tessera/layout/LayoutRegistry.h"

namespace tessera::layout {

class MosaicLayout final : public Layout {
 public:
  // Where the slices sit: a grid of tilesX x tilesY tiles of dims.x x dims.y
  // texels, slice z at column z % tilesX, row z / tilesX, row 0 in the
  // texture's first texel row. Unused tiles at the end of the last row are 0.
  struct Geometry {
    glm::ivec3 dims{0};
    int tilesX = 0;  // 0: the slices do not fit
    int tilesY = 0;
    int width() const { return tilesX * dims.x; }
    int height() const { return tilesY * dims.y; }
    // Texel of voxel (x, y, z): the CPU twin of mosaic.glsl's address maths.
    glm::ivec2 addressOf(int x, int y, int z) const;
  };

  // Texel formats the mosaic may be stored in (see the header comment).
  enum class Storage { R8, R16, R16F, Luminance8 };

  // The grid of at least `tiles` cells of `tile` texels within max2D x max2D
  // with the smallest area, then the squarest; {0, 0} if there is none.
  // Least area first, because memory is what these devices lack: a prime
  // number of slices makes a one-row strip where the max size allows.
  // Non-power-of-two sizes are fine: ES 3 allows them, and ES 2 allows them
  // with CLAMP_TO_EDGE, no mipmaps and LINEAR filtering, which is what we use.
  static glm::ivec2 chooseGrid(glm::ivec2 tile, int tiles, int max2D);
  static Geometry geometryFor(glm::ivec3 dims, int max2D);
  static Storage storageFor(ScalarType type, const gpu::DeviceLimits& limits);

  // The texture image create() uploads for `storage` (as storageFor()
  // picks it), row 0 first, as the host bytes of the storage's upload type
  // (u8 for R8 and Luminance8, u16 for R16, float for R16F); unused tiles 0.
  // create() uploads slice by slice from the same packing code.
  static std::vector<std::uint8_t> pack(const Volume& volume, const Geometry& geometry,
                                        Storage storage);

  // What the layout would allocate for `volume` within `limits` (one
  // texture unit); plan.fits and plan.reason say whether and why (not).
  static LayoutPlan planFor(const Volume& volume, const gpu::DeviceLimits& limits);

  // Plans and uploads. Throws GpuError if the plan does not fit.
  static std::unique_ptr<MosaicLayout> create(const Volume& volume, const gpu::DeviceLimits& limits,
                                              gpu::MemoryLedger& ledger);

  std::string name() const override { return "mosaic"; }
  const LayoutPlan& plan() const override { return plan_; }
  gpu::ShaderPart glsl() const override;
  int bind(const gpu::Program& program, int firstUnit) const override;
  ValueMapping rawFromStored() const override { return mapping_; }
  glm::ivec3 volumeDims() const override { return geometry_.dims; }
  std::uint64_t textureBytes() const override { return texture_.bytes(); }
  int textureUnits() const override { return 1; }

  const Geometry& geometry() const { return geometry_; }
  Storage storage() const { return storage_; }

  // The planner's entry: 2D textures only, costs planFor().
  static LayoutEntry registration();

 private:
  MosaicLayout() = default;
  LayoutPlan plan_;
  Geometry geometry_;
  Storage storage_ = Storage::R8;
  gpu::Texture texture_;
  ValueMapping mapping_;
};

}  // namespace tessera::layout
