#include "tessera/layout/PackedMosaicLayout.h"

#include <algorithm>
#include <cmath>

#include "layout/NormalisedMapping.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/gpu/Draw.h"
#include "tessera/layout/MosaicLayout.h"

namespace tessera::layout {

namespace {

constexpr int kC = PackedMosaicLayout::kChannels;

std::string dimsText(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

const char* packingName(PackedMosaicLayout::Packing p) {
  return p == PackedMosaicLayout::Packing::Overlapped ? "overlapped" : "dense";
}

// Writes tile `tile` (the slices Geometry::sliceAt() names in R, G, B, A; 0
// where it names none) as dims.x * dims.y RGBA8 texels, row y at
// out + y * rowStride.
void packTile(const Volume& volume, const PackedMosaicLayout::Geometry& g, int tile,
              std::uint8_t* out, std::size_t rowStride) {
  const glm::ivec3 d = volume.dims();
  const bool u8 = volume.type() == ScalarType::U8;
  const std::uint8_t* src = u8 ? volume.dataAs<std::uint8_t>() : nullptr;
  ValueRange r;
  double width = 1.0;
  if (!u8) {
    r = volume.valueRange();
    width = r.max > r.min ? r.max - r.min : 1.0;
  }
  for (int c = 0; c < kC; ++c) {
    const int z = g.sliceAt(tile, c);
    for (int y = 0; y < d.y; ++y) {
      std::uint8_t* dst = out + static_cast<std::size_t>(y) * rowStride + c;
      if (z < 0) {
        for (int x = 0; x < d.x; ++x) dst[kC * x] = 0;
      } else if (u8) {
        const std::uint8_t* row = src + volume.index(0, y, z);
        for (int x = 0; x < d.x; ++x) dst[kC * x] = row[x];
      } else {
        // Normalised over the value range and rounded to 8 bits:
        // raw = min + stored * width.
        for (int x = 0; x < d.x; ++x) {
          const double v = volume.valueAtIndex(volume.index(x, y, z));
          const double n = std::isfinite(v) ? std::clamp((v - r.min) / width, 0.0, 1.0) : 0.0;
          dst[kC * x] = static_cast<std::uint8_t>(std::lround(n * 255.0));
        }
      }
    }
  }
}

}  // namespace

int PackedMosaicLayout::Geometry::tiles() const {
  if (packing == Packing::Overlapped) return std::max(1, (dims.z - 1 + 2) / 3);
  return (dims.z + kC - 1) / kC;
}

int PackedMosaicLayout::Geometry::sliceAt(int tile, int channel) const {
  const int z = tile * sliceStride() + channel;
  if (packing == Packing::Overlapped) return std::min(z, dims.z - 1);
  return z < dims.z ? z : -1;
}

PackedMosaicLayout::TexelAddress PackedMosaicLayout::Geometry::tileOrigin(int tile) const {
  const int cell = tile % tilesPerTexture();
  return {tile / tilesPerTexture(), 0, (cell % tilesX) * dims.x, (cell / tilesX) * dims.y};
}

PackedMosaicLayout::TexelAddress PackedMosaicLayout::Geometry::addressOf(int x, int y,
                                                                         int z) const {
  // Overlapped: z = D - 1 with (D - 1) % 3 == 0 would start a tile of its
  // own; it is channel A of the last one.
  const int tile = std::min(z / sliceStride(), tiles() - 1);
  TexelAddress a = tileOrigin(tile);
  a.channel = z - tile * sliceStride();
  a.x += x;
  a.y += y;
  return a;
}

PackedMosaicLayout::Geometry PackedMosaicLayout::geometryFor(glm::ivec3 dims, int max2D,
                                                             Packing packing) {
  Geometry g;
  g.dims = dims;
  g.packing = packing == Packing::Overlapped ? Packing::Overlapped : Packing::Dense;
  if (std::min({dims.x, dims.y, dims.z}) < 1 || dims.x > max2D || dims.y > max2D) return g;
  // Fewest textures first: as many as the tiles need at the largest size...
  const std::int64_t perTexture =
      static_cast<std::int64_t>(max2D / dims.x) * static_cast<std::int64_t>(max2D / dims.y);
  const std::int64_t tiles = g.tiles();
  const std::int64_t textures = (tiles + perTexture - 1) / perTexture;
  // ...then the smallest grid that spreads the tiles evenly over them.
  const auto tilesEach = static_cast<int>((tiles + textures - 1) / textures);
  const glm::ivec2 grid = MosaicLayout::chooseGrid({dims.x, dims.y}, tilesEach, max2D);
  g.textures = static_cast<int>(textures);
  g.tilesX = grid.x;
  g.tilesY = grid.y;
  return g;
}

std::vector<std::vector<std::uint8_t>> PackedMosaicLayout::pack(const Volume& volume,
                                                                const Geometry& geometry) {
  const std::size_t rowStride = static_cast<std::size_t>(geometry.width()) * kC;
  const std::size_t bytes = rowStride * static_cast<std::size_t>(geometry.height());
  HostBudget::global().check(bytes * static_cast<std::size_t>(geometry.textures),
                             "packed-mosaic images");
  std::vector<std::vector<std::uint8_t>> images(static_cast<std::size_t>(geometry.textures),
                                                std::vector<std::uint8_t>(bytes, 0));
  for (int tile = 0; tile < geometry.tiles(); ++tile) {
    const TexelAddress a = geometry.tileOrigin(tile);
    packTile(volume, geometry, tile,
             images[static_cast<std::size_t>(a.texture)].data() +
                 static_cast<std::size_t>(a.y) * rowStride + static_cast<std::size_t>(a.x) * kC,
             rowStride);
  }
  return images;
}

namespace {

struct PackingPlan {
  LayoutPlan plan;
  PackedMosaicLayout::Geometry geometry;
};

// The plan of one packing; the reason says what it allocates and, if it
// does not fit, which limit it breaks (not yet why this packing).
PackingPlan planPacking(const Volume& volume, const gpu::DeviceLimits& limits, int maxTextures,
                        PackedMosaicLayout::Packing packing) {
  PackingPlan result;
  LayoutPlan& plan = result.plan;
  plan.layout = "packed-mosaic";
  const glm::ivec3 d = volume.dims();
  const std::string vol = dimsText(d) + " " + std::string(scalarTypeName(volume.type()));
  const int max2D = limits.max2DTextureSize;
  result.geometry = PackedMosaicLayout::geometryFor(d, max2D, packing);
  const PackedMosaicLayout::Geometry& g = result.geometry;
  if (g.textures == 0) {
    plan.reason = std::min({d.x, d.y, d.z}) < 1
                      ? vol + " is empty"
                      : vol + ": a " + std::to_string(d.x) + "x" + std::to_string(d.y) +
                            " slice exceeds the max 2D texture size " + std::to_string(max2D) +
                            " of " + limits.profile;
    return result;
  }
  const std::string size = std::to_string(g.width()) + "x" + std::to_string(g.height());
  for (int i = 0; i < g.textures; ++i) {
    PlannedTexture t;
    t.label = "volume " + std::to_string(i + 1) + "/" + std::to_string(g.textures);
    t.size = {g.width(), g.height(), 1};
    t.format = "RGBA8";
    t.bytes = static_cast<std::uint64_t>(g.width()) * static_cast<std::uint64_t>(g.height()) * kC;
    plan.textures.push_back(t);
    plan.totalBytes += t.bytes;
  }
  const bool overlapped = g.packing == PackedMosaicLayout::Packing::Overlapped;
  const std::string what =
      vol + " in " + (g.textures == 1 ? "one" : std::to_string(g.textures)) + " RGBA8 " + size +
      (g.textures == 1 ? " texture" : " textures") + " (packed-mosaic " + packingName(g.packing) +
      ", " + std::to_string(g.tilesX) + "x" + std::to_string(g.tilesY) + " tiles of 4 slices" +
      (overlapped ? ", each sharing one with the next," : "") + " per texture, " +
      formatBytes(plan.totalBytes) +
      (volume.type() != ScalarType::U8 ? ", quantised to 8 bits" : "") + ")";
  const int units = std::min(maxTextures, limits.textureUnits);
  if (g.textures > PackedMosaicLayout::kMaxTextures) {
    plan.reason = what + " needs more than the " +
                  std::to_string(PackedMosaicLayout::kMaxTextures) +
                  " textures packed-mosaic can address";
  } else if (g.textures > units) {
    plan.reason = what + " needs " + std::to_string(g.textures) + " texture units, " +
                  std::to_string(std::max(units, 0)) + " left for the volume on " + limits.profile;
  } else if (limits.textureBudget != 0 && plan.totalBytes > limits.textureBudget) {
    plan.reason = what + " exceeds the texture budget " + formatBytes(limits.textureBudget) +
                  " of " + limits.profile;
  } else {
    plan.fits = true;
    plan.reason = what;
  }
  return result;
}

// The packing planFor() and create() use, and why (PackedMosaicLayout.h).
PackingPlan choosePacking(const Volume& volume, const gpu::DeviceLimits& limits, int maxTextures,
                          PackedMosaicLayout::Packing packing) {
  using Packing = PackedMosaicLayout::Packing;
  if (packing != Packing::Auto) {
    PackingPlan forced = planPacking(volume, limits, maxTextures, packing);
    if (forced.plan.fits) {
      forced.plan.reason += packing == Packing::Overlapped
                                ? "; overlapped (as asked): one fetch per sample"
                                : "; dense (as asked)";
    }
    return forced;
  }
  PackingPlan dense = planPacking(volume, limits, maxTextures, Packing::Dense);
  PackingPlan overlapped = planPacking(volume, limits, maxTextures, Packing::Overlapped);
  if (overlapped.plan.fits && overlapped.geometry.textures <= dense.geometry.textures) {
    overlapped.plan.reason += "; overlapped: one fetch per sample";
    return overlapped;
  }
  // Overlapped needs at least dense's tiles, so it fits nowhere dense does
  // not: a refused dense plan is the one to explain.
  if (!dense.plan.fits) return dense;
  if (overlapped.geometry.textures > dense.geometry.textures) {
    dense.plan.reason += "; dense: overlapped would need " +
                         std::to_string(overlapped.geometry.textures) + " textures instead of " +
                         std::to_string(dense.geometry.textures);
  } else if (limits.textureBudget != 0 && overlapped.plan.totalBytes > limits.textureBudget) {
    dense.plan.reason += "; dense: overlapped (" + formatBytes(overlapped.plan.totalBytes) +
                         ") would exceed the texture budget " + formatBytes(limits.textureBudget);
  } else {
    dense.plan.reason += "; dense: overlapped does not fit: " + overlapped.plan.reason;
  }
  return dense;
}

}  // namespace

LayoutPlan PackedMosaicLayout::planFor(const Volume& volume, const gpu::DeviceLimits& limits,
                                       int maxTextures, Packing packing) {
  return choosePacking(volume, limits, maxTextures, packing).plan;
}

std::unique_ptr<PackedMosaicLayout> PackedMosaicLayout::create(const Volume& volume,
                                                               const gpu::DeviceLimits& limits,
                                                               gpu::MemoryLedger& ledger,
                                                               int maxTextures, Packing packing) {
  std::unique_ptr<PackedMosaicLayout> l(new PackedMosaicLayout());
  l->voxels_ = &volume;
  PackingPlan chosen = choosePacking(volume, limits, maxTextures, packing);
  l->plan_ = std::move(chosen.plan);
  if (!l->plan_.fits) throw GpuError("packed-mosaic layout: " + l->plan_.reason);
  l->geometry_ = chosen.geometry;
  l->mapping_ = normalisedMapping(volume);
  const Geometry& g = l->geometry_;
  // ES 2.0 takes only unsized internal formats.
  const gpu::TexelFormat format = gpu::rgba8For(limits.api);
  // Tile by tile, so the host needs one tile of staging, not whole textures;
  // the unused tiles of the last texture get zeros (glTexImage2D with no
  // data leaves them undefined).
  const std::size_t rowStride = static_cast<std::size_t>(g.dims.x) * kC;
  const std::size_t tileBytes = rowStride * static_cast<std::size_t>(g.dims.y);
  HostBudget::global().check(tileBytes, "packed-mosaic upload staging");
  std::vector<std::uint8_t> staging(tileBytes);
  for (int t = 0; t < g.textures; ++t) {
    l->textures_.push_back(gpu::Texture::create2D(
        ledger,
        "volume (packed-mosaic " + std::string(packingName(g.packing)) + " RGBA8 " +
            std::to_string(t + 1) + "/" + std::to_string(g.textures) + ")",
        format, g.width(), g.height()));
    for (int cell = 0; cell < g.tilesPerTexture(); ++cell) {
      const int tile = t * g.tilesPerTexture() + cell;
      if (tile < g.tiles()) {
        packTile(volume, g, tile, staging.data(), rowStride);
      } else {
        std::fill(staging.begin(), staging.end(), std::uint8_t{0});
      }
      l->textures_.back().updateRegion(
          {(cell % g.tilesX) * g.dims.x, (cell / g.tilesX) * g.dims.y, 0}, {g.dims.x, g.dims.y, 1},
          staging.data());
    }
  }
  gpu::checkErrors("packed-mosaic layout: uploading " + std::to_string(g.textures) + " RGBA8 " +
                   std::to_string(g.width()) + "x" + std::to_string(g.height()) + " textures");
  return l;
}

gpu::ShaderPart PackedMosaicLayout::glsl() const {
  gpu::ShaderPart part = gpu::embeddedShaderPart("layout/packed_mosaic.glsl");
  // The sampler count must be a compile-time constant (sampler arrays take
  // constant indices only), and the packing picks the code; they replace
  // the file's first two lines, comments, so that compile errors keep the
  // file's line numbers.
  const std::size_t secondLineEnd = part.text.find('\n', part.text.find('\n') + 1);
  part.text.replace(0, secondLineEnd,
                    "#define TESSERA_PACKED_TEXTURES " + std::to_string(geometry_.textures) +
                        "\n#define TESSERA_PACKED_OVERLAPPED " +
                        (geometry_.packing == Packing::Overlapped ? "1" : "0"));
  return part;
}

int PackedMosaicLayout::bind(const gpu::Program& program, int firstUnit) const {
  for (int i = 0; i < geometry_.textures; ++i) {
    textures_[static_cast<std::size_t>(i)].bind(firstUnit + i);
    program.set(("u_layoutTextures[" + std::to_string(i) + "]").c_str(), firstUnit + i);
  }
  program.set("u_layoutDims", glm::vec3(geometry_.dims));
  const glm::vec2 tiles(static_cast<float>(geometry_.tilesX), static_cast<float>(geometry_.tilesY));
  program.set("u_layoutTiles", tiles);
  program.set("u_layoutInvTiles", 1.0f / tiles);
  program.set("u_layoutInvSize", glm::vec2(1.0f / static_cast<float>(geometry_.width()),
                                           1.0f / static_cast<float>(geometry_.height())));
  return geometry_.textures;
}

std::uint64_t PackedMosaicLayout::textureBytes() const {
  std::uint64_t total = 0;
  for (const gpu::Texture& t : textures_) total += t.bytes();
  return total;
}

LayoutEntry PackedMosaicLayout::registration() {
  return {.name = "packed-mosaic",
          .plan = [](const Volume& shape, const gpu::DeviceLimits& limits,
                     int units) { return planFor(shape, limits, units); },
          .create = [](const Volume& volume, const gpu::DeviceLimits& limits,
                       gpu::MemoryLedger& ledger, int units) -> std::unique_ptr<Layout> {
            return create(volume, limits, ledger, units);
          }};
}

}  // namespace tessera::layout
