#pragma once
// The three axis-aligned stacks of 2D slices of axis-aligned slicing (Moser
// & Weiskopf 2008, section 4): the volume quantised once to 8-bit indices
// through its value window (the host copy every TF change is classified
// from), and the atlas plan of each stack — slices tiled in a grid, without
// rotation, in as few textures as the maximum texture size allows,
// power-of-two sized where the device needs it.
//
// Tile (u, v) of slice i of stack `axis` is the voxel with coordinate i
// along the axis and (u, v) along the other two axes in x, y, z order:
// x stack (y, z), y stack (x, z), z stack (x, y).
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"

namespace tessera::render {

struct SliceAtlasPlan {
  int axis = 2;
  glm::ivec2 tile{0};  // texels of one slice
  int slices = 0;
  int atlases = 0;
  int tilesPerAtlas = 0;  // the last atlas may hold fewer
  int columns = 0;        // grid of each atlas
  int rows = 0;
  glm::ivec2 atlasSize{0};  // texels; every atlas of the stack has this size

  int atlasOf(int slice) const { return slice / tilesPerAtlas; }
  // Texel of the tile's lower-left corner inside its atlas.
  glm::ivec2 tileOrigin(int slice) const {
    const int t = slice % tilesPerAtlas;
    return {(t % columns) * tile.x, (t / columns) * tile.y};
  }
  // Texel rows of an atlas in bands one tile row high (the last may be a
  // shorter band of power-of-two padding): the unit the slices are uploaded
  // in, so that a TF change never needs a host copy of a whole atlas.
  int bands() const { return (atlasSize.y + tile.y - 1) / tile.y; }
  int bandRows(int band) const { return std::min(tile.y, atlasSize.y - band * tile.y); }
  std::string describe() const;  // "3 x 1024x2048" style, for reports
};

// The axes a stack's tiles span: (u, v) for stack `axis`.
glm::ivec2 sliceTileAxes(int axis);

// Smallest grid (by texture area, then squareness) holding the stack's
// slices in atlases of at most maxTextureSize texels a side. GpuError when a
// single slice is larger than that.
SliceAtlasPlan planSliceAtlas(glm::ivec3 dims, int axis, int maxTextureSize, bool powerOfTwo);

class SliceStacks {
 public:
  // Quantises `volume` through its window: index = round(255 n).
  explicit SliceStacks(const Volume& volume);

  glm::ivec3 dims() const { return dims_; }
  const std::vector<std::uint8_t>& indices() const { return indices_; }
  std::uint8_t indexAt(int x, int y, int z) const {
    return indices_[(static_cast<std::size_t>(z) * dims_.y + y) * dims_.x + x];
  }

  // One atlas image, bottom row first, tightly packed: 1 byte per texel of
  // indices when `palette` is null, else 4 bytes of palette[index] (the
  // CPU classification of pre-classified slicing; palette: 256 RGBA8).
  // Texels outside every tile stay 0.
  void fillAtlas(const SliceAtlasPlan& plan, int atlas, const std::uint8_t* palette,
                 std::vector<std::uint8_t>& out) const;
  // Band `band` of that image (texel rows band * tile.y onwards, bandRows of
  // them), the same bytes fillAtlas writes there.
  void fillAtlasBand(const SliceAtlasPlan& plan, int atlas, int band, const std::uint8_t* palette,
                     std::vector<std::uint8_t>& out) const;
  // The same band for shaded slicing: 4 bytes per texel, the index of the
  // slice (R) and of its neighbours along the stack axis below (G) and above
  // (B), clamped at the stack's ends, A = 255. Filtered bilinearly, G and B
  // are the field one voxel either side of the plane, so the shader takes
  // central differences along the axis from the slice's own texel (the
  // gradient the reference takes at a voxel plane).
  void fillShadingAtlasBand(const SliceAtlasPlan& plan, int atlas, int band,
                            std::vector<std::uint8_t>& out) const;

 private:
  // Texel rows [y0, y1) of an atlas image into `out`, resized to fit them.
  void fillAtlasRows(const SliceAtlasPlan& plan, int atlas, int y0, int y1,
                     const std::uint8_t* palette, std::vector<std::uint8_t>& out) const;

  glm::ivec3 dims_{0};
  std::vector<std::uint8_t> indices_;
};

}  // namespace tessera::render
