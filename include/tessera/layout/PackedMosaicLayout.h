#pragma once
// The volume in the R, G, B and A channels of up to N RGBA8 2D textures
// (Noguera & Jiménez 2012, "Visualization of very large 3D volumes on mobile
// devices and WebGL"): four times the voxels of a mosaic per texture, and
// every texture unit the technique leaves free, so 512x512x384 fits six
// 2048^2 textures (an iPad 2) and 512x512x1024 one 8192^2 texture.
//
// Packing — ours, not the paper's. The paper fills channel R of texture 0
// with a whole mosaic of consecutive slices, then G, B, A, then the next
// texture, so the two slices of one trilinear sample are in the same channel
// of the same texture except at a mosaic's end. We put slice s in channel
// s % 4 of tile g = s / 4, and tile g in texture g / T at grid position
// g % T (T tiles per texture). Why it is better:
//   - the four slices of a texel are neighbours in z, so the z0 and z1
//     fetches of a sample read the same texel 3 times out of 4 (the second
//     fetch is a texture-cache hit); in the paper's packing z0 and z1 always
//     sit in different tiles, and the other three channels of every fetched
//     texel hold slices a whole mosaic (Mx * My slices) away, of no use to
//     the sample;
//   - the address maths is the mosaic's plus two floors (tile, texture)
//     and one dot(): channel = s - 4 * floor(s / 4), selected branch-free with
//     dot(texel, vec4(equal(vec4(channel), vec4(0, 1, 2, 3)))), where the
//     paper needs mod(aux + 1, S_tex) wrap-arounds and step() carries to
//     move to the next channel and texture;
//   - a partly filled last texture wastes only whole unused tiles.
// Seams (z between channel 3 of one tile and channel 0 of the next, or
// between the last tile of one texture and the first of the next) cost
// nothing special: z0 and z1 are addressed independently.
//
// Every type is stored in 8 bits: u8 exactly; u16, i16 and f32 normalised
// over the value range and rounded to 8 bits (a loss of up to half a step of
// (max - min) / 255 per voxel) — RGBA8 is the one four-channel format every
// ES 2.0 device filters.
#include <cstdint>
#include <memory>
#include <vector>

#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/MemoryLedger.h"
#include "tessera/layout/Layout.h"

namespace tessera::layout {

class PackedMosaicLayout final : public Layout {
 public:
  // Samplers packed_mosaic.glsl can select among (its if/else chain).
  static constexpr int kMaxTextures = 16;
  static constexpr int kChannels = 4;

  struct TexelAddress {
    int texture = 0;
    int channel = 0;  // 0..3 = R, G, B, A
    int x = 0;
    int y = 0;
  };

  // Where the slices sit: `textures` textures of the same size, each a grid
  // of tilesX x tilesY tiles of dims.x x dims.y RGBA texels, row 0 of the
  // grid in the texture's first texel row.
  struct Geometry {
    glm::ivec3 dims{0};
    int textures = 0;  // 0: a slice does not fit in max2D
    int tilesX = 0;
    int tilesY = 0;
    int tilesPerTexture() const { return tilesX * tilesY; }
    int tiles() const { return (dims.z + kChannels - 1) / kChannels; }
    int width() const { return tilesX * dims.x; }
    int height() const { return tilesY * dims.y; }
    // Texture, channel and texel of voxel (x, y, z): the CPU twin of
    // packed_mosaic.glsl's address maths.
    TexelAddress addressOf(int x, int y, int z) const;
  };

  // The fewest textures of at most max2D x max2D that hold the volume, then
  // the smallest (squarest) tile grid that spreads the tiles over them. The
  // number of texture units it needs is `textures`, whatever the device has.
  static Geometry geometryFor(glm::ivec3 dims, int max2D);

  // The RGBA8 images create() uploads (one per texture, row 0 first, 4
  // bytes per texel, unused channels and tiles 0), built by the same
  // per-tile packing create() uploads tile by tile.
  static std::vector<std::vector<std::uint8_t>> pack(const Volume& volume,
                                                     const Geometry& geometry);

  // What the layout would allocate for `volume` within `limits` using at most
  // `maxTextures` texture units (the caller has reserved the technique's);
  // plan.fits and plan.reason say whether and why (not).
  static LayoutPlan planFor(const Volume& volume, const gpu::DeviceLimits& limits, int maxTextures);

  // Plans and uploads. Throws GpuError if the plan does not fit.
  static std::unique_ptr<PackedMosaicLayout> create(const Volume& volume,
                                                    const gpu::DeviceLimits& limits,
                                                    gpu::MemoryLedger& ledger, int maxTextures);

  std::string name() const override { return "packed-mosaic"; }
  const LayoutPlan& plan() const override { return plan_; }
  gpu::ShaderPart glsl() const override;
  int bind(const gpu::Program& program, int firstUnit) const override;
  ValueMapping rawFromStored() const override { return mapping_; }
  glm::ivec3 volumeDims() const override { return geometry_.dims; }
  std::uint64_t textureBytes() const override;
  int textureUnits() const override { return geometry_.textures; }

  const Geometry& geometry() const { return geometry_; }

 private:
  PackedMosaicLayout() = default;
  LayoutPlan plan_;
  Geometry geometry_;
  std::vector<gpu::Texture> textures_;
  ValueMapping mapping_;
};

}  // namespace tessera::layout
