#pragma once
// The volume in the R, G, B and A channels of up to N RGBA8 2D textures
// (Noguera & Jiménez 2012, "Visualization of very large 3D volumes on mobile
// devices and WebGL"): four times the voxels of a mosaic per texture, and
// every texture unit the technique leaves free, so 512x512x384 fits six
// 2048^2 textures (an iPad 2) and 512x512x1024 one 8192^2 texture.
//
// Two packings, both ours, not the paper's (which fills channel R of
// texture 0 with a whole mosaic of consecutive slices, then G, B, A, then
// the next texture, so z0 and z1 of a sample always sit in different tiles
// and the other three channels of a fetched texel hold slices a whole mosaic
// away, of no use to the sample, and needs mod(aux + 1, S_tex) wrap-arounds
// and step() carries to move on to the next channel and texture).
//
// Dense: slice s in channel s % 4 of tile g = s / 4 — ceil(D / 4) tiles, the
// paper's capacity. The two slices of a trilinear sample are addressed
// independently: two bilinear RGBA fetches, which read the same texel 3
// times out of 4 (the second is a texture-cache hit, but still a fetch and
// on a multi-texture layout a second walk down the sampler if-chain).
//
// Overlapped: tile g holds slices 3g, 3g+1, 3g+2, 3g+3 in R, G, B, A
// (channel c = slice min(3g + c, D - 1)), so every tile repeats the last
// slice of the previous one. Every pair of neighbouring slices (z0, z0 + 1)
// then lies in one texel — tile floor(z0 / 3), channels z0 - 3g and one
// more — and a trilinear sample is ONE bilinear RGBA fetch and a dot() with
// hat weights over the channels. The price: ceil((D - 1) / 3) tiles instead
// of ceil(D / 4), a third more texture memory.
//
// Which: Packing::Auto takes overlapped when it fits the same limits (max 2D
// size, budget) in no more textures than dense. Not when it needs more:
// texture units are what the ES 2.0 devices this layout exists for run out
// of, and the paper's capacities (512x512x384 in six 2048^2 textures, 8
// overlapped; 512x512x1024 in one 8192^2, 2 overlapped) stay dense.
//
// In both, tile g sits in texture g / T at grid position g % T (T tiles per
// texture), and the address maths is the mosaic's plus two floors (tile,
// texture); channels are selected branch-free (one-hot or hat weights from
// the channel index, never rgba[int(c)]); a partly filled last texture
// wastes only whole unused tiles.
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
#include "tessera/layout/LayoutRegistry.h"

namespace tessera::layout {

class PackedMosaicLayout final : public Layout {
 public:
  // Samplers packed_mosaic.glsl can select among (its if/else chain).
  static constexpr int kMaxTextures = 16;
  static constexpr int kChannels = 4;

  // See the file comment. Auto is a request only; a geometry or a layout is
  // always Dense or Overlapped.
  enum class Packing { Auto, Dense, Overlapped };

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
    Packing packing = Packing::Dense;
    int textures = 0;  // 0: a slice does not fit in max2D
    int tilesX = 0;
    int tilesY = 0;
    int tilesPerTexture() const { return tilesX * tilesY; }
    // Slices a tile starts after the previous one: 4 (dense) or 3
    // (overlapped, whose channel A repeats as the next tile's R).
    int sliceStride() const { return packing == Packing::Overlapped ? 3 : kChannels; }
    // Dense: ceil(D / 4). Overlapped: ceil((D - 1) / 3), at least 1.
    int tiles() const;
    int width() const { return tilesX * dims.x; }
    int height() const { return tilesY * dims.y; }
    // The slice channel `channel` of tile `tile` holds; -1: none (dense
    // past the last slice, where pack() stores 0). Overlapped repeats slice
    // D - 1 in the channels past it, so that the pair (D - 2, D - 1) — and,
    // for D = 1, (0, 0) — sits in one texel like every other.
    int sliceAt(int tile, int channel) const;
    // Texture and texel (channel 0) of the first texel of tile `tile`.
    TexelAddress tileOrigin(int tile) const;
    // Texture, channel and texel of voxel (x, y, z): the CPU twin of
    // packed_mosaic.glsl's address maths. Overlapped stores a voxel twice
    // when z = 3g with 0 < g < tiles() (channel A of tile g - 1, channel R
    // of tile g) and up to 4 times for z = D - 1; addressOf() gives the
    // primary copy, tile min(z / 3, tiles() - 1) channel z - 3 * tile, the
    // one the shader reads for z0 = z.
    TexelAddress addressOf(int x, int y, int z) const;
  };

  // The fewest textures of at most max2D x max2D that hold the volume's
  // tiles in `packing` (Auto is taken as Dense: choosing needs the unit and
  // budget limits planFor() has), then the smallest (squarest) tile grid
  // that spreads the tiles over them. The number of texture units it needs
  // is `textures`, whatever the device has.
  static Geometry geometryFor(glm::ivec3 dims, int max2D, Packing packing = Packing::Dense);

  // The RGBA8 images create() uploads (one per texture, row 0 first, 4
  // bytes per texel, unused channels and tiles 0), built by the same
  // per-tile packing create() uploads tile by tile.
  static std::vector<std::vector<std::uint8_t>> pack(const Volume& volume,
                                                     const Geometry& geometry);

  // What the layout would allocate for `volume` within `limits` using at most
  // `maxTextures` texture units (the caller has reserved the technique's);
  // plan.fits and plan.reason say whether and why (not), and the reason
  // names the packing and why it was chosen. `packing` forces one (tests,
  // benchmarks); Auto chooses as the file comment says.
  static LayoutPlan planFor(const Volume& volume, const gpu::DeviceLimits& limits, int maxTextures,
                            Packing packing = Packing::Auto);

  // Plans and uploads. Throws GpuError if the plan does not fit.
  static std::unique_ptr<PackedMosaicLayout> create(const Volume& volume,
                                                    const gpu::DeviceLimits& limits,
                                                    gpu::MemoryLedger& ledger, int maxTextures,
                                                    Packing packing = Packing::Auto);

  std::string name() const override { return "packed-mosaic"; }
  const LayoutPlan& plan() const override { return plan_; }
  gpu::ShaderPart glsl() const override;
  int bind(const gpu::Program& program, int firstUnit) const override;
  ValueMapping rawFromStored() const override { return mapping_; }
  glm::ivec3 volumeDims() const override { return geometry_.dims; }
  std::uint64_t textureBytes() const override;
  int textureUnits() const override { return geometry_.textures; }

  const Geometry& geometry() const { return geometry_; }
  Packing packing() const { return geometry_.packing; }

  // The planner's entry: 2D textures only, costs planFor() with the units left.
  static LayoutEntry registration();

 private:
  PackedMosaicLayout() = default;
  LayoutPlan plan_;
  Geometry geometry_;
  std::vector<gpu::Texture> textures_;
  ValueMapping mapping_;
};

}  // namespace tessera::layout
