#include "tessera/layout/PackedMosaicLayout.h"

#include <algorithm>
#include <cmath>

#include "gpu/gl.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/layout/MosaicLayout.h"

namespace tessera::layout {

namespace {

constexpr int kC = PackedMosaicLayout::kChannels;

std::string dimsText(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

// Writes tile `tile` (slices 4 * tile .. 4 * tile + 3 in R, G, B, A; 0 past
// the last slice) as dims.x * dims.y RGBA8 texels, row y at out + y * rowStride.
void packTile(const Volume& volume, int tile, std::uint8_t* out, std::size_t rowStride) {
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
    const int z = tile * kC + c;
    for (int y = 0; y < d.y; ++y) {
      std::uint8_t* dst = out + static_cast<std::size_t>(y) * rowStride + c;
      if (z >= d.z) {
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

PackedMosaicLayout::TexelAddress PackedMosaicLayout::Geometry::addressOf(int x, int y,
                                                                         int z) const {
  const int tile = z / kC;
  const int cell = tile % tilesPerTexture();
  return {tile / tilesPerTexture(), z % kC, (cell % tilesX) * dims.x + x,
          (cell / tilesX) * dims.y + y};
}

PackedMosaicLayout::Geometry PackedMosaicLayout::geometryFor(glm::ivec3 dims, int max2D) {
  Geometry g;
  g.dims = dims;
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
    const TexelAddress a = geometry.addressOf(0, 0, tile * kC);
    packTile(volume, tile,
             images[static_cast<std::size_t>(a.texture)].data() +
                 static_cast<std::size_t>(a.y) * rowStride + static_cast<std::size_t>(a.x) * kC,
             rowStride);
  }
  return images;
}

LayoutPlan PackedMosaicLayout::planFor(const Volume& volume, const gpu::DeviceLimits& limits,
                                       int maxTextures) {
  LayoutPlan plan;
  plan.layout = "packed-mosaic";
  const glm::ivec3 d = volume.dims();
  const std::string vol = dimsText(d) + " " + std::string(scalarTypeName(volume.type()));
  const int max2D = limits.max2DTextureSize;
  const Geometry g = geometryFor(d, max2D);
  if (g.textures == 0) {
    plan.reason = std::min({d.x, d.y, d.z}) < 1
                      ? vol + " is empty"
                      : vol + ": a " + std::to_string(d.x) + "x" + std::to_string(d.y) +
                            " slice exceeds the max 2D texture size " + std::to_string(max2D) +
                            " of " + limits.profile;
    return plan;
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
  const std::string what = vol + " in " + (g.textures == 1 ? "one" : std::to_string(g.textures)) +
                           " RGBA8 " + size + (g.textures == 1 ? " texture" : " textures") +
                           " (packed-mosaic, " + std::to_string(g.tilesX) + "x" +
                           std::to_string(g.tilesY) + " tiles of 4 slices per texture, " +
                           formatBytes(plan.totalBytes) +
                           (volume.type() != ScalarType::U8 ? ", quantised to 8 bits" : "") + ")";
  const int units = std::min(maxTextures, limits.textureUnits);
  if (g.textures > kMaxTextures) {
    plan.reason = what + " needs more than the " + std::to_string(kMaxTextures) +
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
  return plan;
}

std::unique_ptr<PackedMosaicLayout> PackedMosaicLayout::create(const Volume& volume,
                                                               const gpu::DeviceLimits& limits,
                                                               gpu::MemoryLedger& ledger,
                                                               int maxTextures) {
  std::unique_ptr<PackedMosaicLayout> l(new PackedMosaicLayout());
  l->plan_ = planFor(volume, limits, maxTextures);
  if (!l->plan_.fits) throw GpuError("packed-mosaic layout: " + l->plan_.reason);
  l->geometry_ = geometryFor(volume.dims(), limits.max2DTextureSize);
  if (volume.type() == ScalarType::U8) {
    l->mapping_ = {255.0, 0.0};
  } else {
    const ValueRange r = volume.valueRange();
    l->mapping_ = {r.max > r.min ? r.max - r.min : 1.0, r.min};
  }
  const Geometry& g = l->geometry_;
  // ES 2.0 takes only unsized internal formats.
  const GLenum internalFormat = limits.api == gpu::ApiLevel::Gles2 ? GL_RGBA : GL_RGBA8;
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
        "volume (packed-mosaic RGBA8 " + std::to_string(t + 1) + "/" + std::to_string(g.textures) +
            ")",
        internalFormat, g.width(), g.height(), GL_RGBA, GL_UNSIGNED_BYTE, nullptr, kC));
    glBindTexture(GL_TEXTURE_2D, l->textures_.back().id());
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    for (int cell = 0; cell < g.tilesPerTexture(); ++cell) {
      const int tile = t * g.tilesPerTexture() + cell;
      if (tile < g.tiles()) {
        packTile(volume, tile, staging.data(), rowStride);
      } else {
        std::fill(staging.begin(), staging.end(), std::uint8_t{0});
      }
      glTexSubImage2D(GL_TEXTURE_2D, 0, (cell % g.tilesX) * g.dims.x, (cell / g.tilesX) * g.dims.y,
                      g.dims.x, g.dims.y, GL_RGBA, GL_UNSIGNED_BYTE, staging.data());
    }
  }
  const GLenum err = glGetError();
  if (err != GL_NO_ERROR) {
    throw GpuError("packed-mosaic layout: uploading " + std::to_string(g.textures) + " RGBA8 " +
                   std::to_string(g.width()) + "x" + std::to_string(g.height()) +
                   " textures failed with GL error " + std::to_string(err));
  }
  return l;
}

gpu::ShaderPart PackedMosaicLayout::glsl() const {
  gpu::ShaderPart part = gpu::embeddedShaderPart("layout/packed_mosaic.glsl");
  // The sampler count must be a compile-time constant (sampler arrays take
  // constant indices only); it replaces the file's first line, a comment, so
  // that compile errors keep the file's line numbers.
  const std::size_t firstLineEnd = part.text.find('\n');
  part.text.replace(0, firstLineEnd,
                    "#define TESSERA_PACKED_TEXTURES " + std::to_string(geometry_.textures));
  return part;
}

int PackedMosaicLayout::bind(const gpu::Program& program, int firstUnit) const {
  for (int i = 0; i < geometry_.textures; ++i) {
    textures_[static_cast<std::size_t>(i)].bind(firstUnit + i);
    program.set(("u_layoutTextures[" + std::to_string(i) + "]").c_str(), firstUnit + i);
  }
  program.set("u_layoutDims", glm::vec3(geometry_.dims));
  program.set("u_layoutTilesX", static_cast<float>(geometry_.tilesX));
  program.set("u_layoutTilesPerTexture", static_cast<float>(geometry_.tilesPerTexture()));
  program.set("u_layoutInvSize", glm::vec2(1.0f / static_cast<float>(geometry_.width()),
                                           1.0f / static_cast<float>(geometry_.height())));
  return geometry_.textures;
}

std::uint64_t PackedMosaicLayout::textureBytes() const {
  std::uint64_t total = 0;
  for (const gpu::Texture& t : textures_) total += t.bytes();
  return total;
}

}  // namespace tessera::layout
