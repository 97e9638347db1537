#include "tessera/layout/MosaicLayout.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "layout/NormalisedMapping.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/gpu/Draw.h"

namespace tessera::layout {

namespace {

std::string dimsText(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

gpu::TexelFormat formatOf(MosaicLayout::Storage s) {
  switch (s) {
    case MosaicLayout::Storage::R8:
      return gpu::TexelFormat::R8;
    case MosaicLayout::Storage::R16:
      return gpu::TexelFormat::R16;
    case MosaicLayout::Storage::R16F:
      return gpu::TexelFormat::R16F;
    case MosaicLayout::Storage::Luminance8:
      return gpu::TexelFormat::Luminance8;
  }
  return gpu::TexelFormat::R8;
}

// Writes slice z as dims.x * dims.y texels of the storage's upload type,
// row y at out + y * rowStride bytes.
void packSlice(const Volume& volume, int z, MosaicLayout::Storage storage, std::uint8_t* out,
               std::size_t rowStride) {
  const glm::ivec3 d = volume.dims();
  const std::size_t row = static_cast<std::size_t>(d.x);
  const bool eightBit =
      storage == MosaicLayout::Storage::R8 || storage == MosaicLayout::Storage::Luminance8;
  if (volume.type() == ScalarType::U8 && eightBit) {  // exact
    const std::uint8_t* src = volume.dataAs<std::uint8_t>();
    for (int y = 0; y < d.y; ++y) {
      std::memcpy(out + static_cast<std::size_t>(y) * rowStride, src + volume.index(0, y, z), row);
    }
    return;
  }
  // Normalised over the value range: raw = min + stored * width.
  const ValueRange r = volume.valueRange();
  const double width = r.max > r.min ? r.max - r.min : 1.0;
  for (int y = 0; y < d.y; ++y) {
    std::uint8_t* dst = out + static_cast<std::size_t>(y) * rowStride;
    for (int x = 0; x < d.x; ++x) {
      const double v = volume.valueAtIndex(volume.index(x, y, z));
      const double n = std::isfinite(v) ? std::clamp((v - r.min) / width, 0.0, 1.0) : 0.0;
      switch (storage) {
        case MosaicLayout::Storage::R8:
        case MosaicLayout::Storage::Luminance8:
          dst[x] = static_cast<std::uint8_t>(std::lround(n * 255.0));
          break;
        case MosaicLayout::Storage::R16: {
          const auto q = static_cast<std::uint16_t>(std::lround(n * 65535.0));
          std::memcpy(dst + 2 * static_cast<std::size_t>(x), &q, 2);
          break;
        }
        case MosaicLayout::Storage::R16F: {
          const auto f = static_cast<float>(n);
          std::memcpy(dst + 4 * static_cast<std::size_t>(x), &f, 4);
          break;
        }
      }
    }
  }
}

}  // namespace

glm::ivec2 MosaicLayout::Geometry::addressOf(int x, int y, int z) const {
  return {(z % tilesX) * dims.x + x, (z / tilesX) * dims.y + y};
}

glm::ivec2 MosaicLayout::chooseGrid(glm::ivec2 tile, int tiles, int max2D) {
  if (tile.x < 1 || tile.y < 1 || tiles < 1) return {0, 0};
  const int maxX = max2D / tile.x;
  const int maxY = max2D / tile.y;
  glm::ivec2 best{0, 0};
  std::uint64_t bestArea = std::numeric_limits<std::uint64_t>::max();
  int bestSide = std::numeric_limits<int>::max();
  for (int tx = 1; tx <= std::min(tiles, maxX); ++tx) {
    const int ty = (tiles + tx - 1) / tx;
    if (ty > maxY) continue;
    const int w = tx * tile.x;
    const int h = ty * tile.y;
    const std::uint64_t area = static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h);
    const int side = std::max(w, h);
    if (area < bestArea || (area == bestArea && side < bestSide)) {
      best = {tx, ty};
      bestArea = area;
      bestSide = side;
    }
  }
  return best;
}

MosaicLayout::Geometry MosaicLayout::geometryFor(glm::ivec3 dims, int max2D) {
  Geometry g;
  g.dims = dims;
  const glm::ivec2 grid = chooseGrid({dims.x, dims.y}, dims.z, max2D);
  g.tilesX = grid.x;
  g.tilesY = grid.y;
  return g;
}

MosaicLayout::Storage MosaicLayout::storageFor(ScalarType type, const gpu::DeviceLimits& limits) {
  if (limits.api == gpu::ApiLevel::Gles2) return Storage::Luminance8;
  if (type == ScalarType::U8) return Storage::R8;
  return limits.norm16Textures ? Storage::R16 : Storage::R16F;
}

std::vector<std::uint8_t> MosaicLayout::pack(const Volume& volume, const Geometry& geometry,
                                             Storage storage) {
  const std::size_t hostBytes = gpu::uploadBytesPerTexel(formatOf(storage));
  const std::size_t rowStride = static_cast<std::size_t>(geometry.width()) * hostBytes;
  const std::size_t bytes = rowStride * static_cast<std::size_t>(geometry.height());
  HostBudget::global().check(bytes, "mosaic image");
  std::vector<std::uint8_t> image(bytes, 0);
  for (int z = 0; z < geometry.dims.z; ++z) {
    const glm::ivec2 origin = geometry.addressOf(0, 0, z);
    packSlice(volume, z, storage,
              image.data() + static_cast<std::size_t>(origin.y) * rowStride +
                  static_cast<std::size_t>(origin.x) * hostBytes,
              rowStride);
  }
  return image;
}

LayoutPlan MosaicLayout::planFor(const Volume& volume, const gpu::DeviceLimits& limits) {
  LayoutPlan plan;
  plan.layout = "mosaic";
  const glm::ivec3 d = volume.dims();
  const std::string vol = dimsText(d) + " " + std::string(scalarTypeName(volume.type()));
  const int max2D = limits.max2DTextureSize;
  const Geometry g = geometryFor(d, max2D);
  if (g.tilesX == 0) {
    if (std::min({d.x, d.y, d.z}) < 1) {
      plan.reason = vol + " is empty";
    } else if (d.x > max2D || d.y > max2D) {
      plan.reason = vol + ": a " + std::to_string(d.x) + "x" + std::to_string(d.y) +
                    " slice exceeds the max 2D texture size " + std::to_string(max2D) + " of " +
                    limits.profile;
    } else {
      const std::uint64_t cells =
          static_cast<std::uint64_t>(max2D / d.x) * static_cast<std::uint64_t>(max2D / d.y);
      plan.reason = vol + ": " + std::to_string(d.z) + " slices do not fit one " +
                    std::to_string(max2D) + "x" + std::to_string(max2D) + " mosaic (" +
                    std::to_string(cells) + " tiles, the max 2D texture size of " + limits.profile +
                    ")";
    }
    return plan;
  }
  const Storage storage = storageFor(volume.type(), limits);
  const gpu::TexelFormat f = formatOf(storage);
  const std::uint64_t gpuBytes = gpu::bytesPerTexel(f);
  PlannedTexture t;
  t.label = "volume mosaic";
  t.size = {g.width(), g.height(), 1};
  t.format = gpu::texelFormatName(f);
  t.bytes =
      static_cast<std::uint64_t>(g.width()) * static_cast<std::uint64_t>(g.height()) * gpuBytes;
  plan.textures.push_back(t);
  plan.totalBytes = t.bytes;
  const bool quantised = volume.type() != ScalarType::U8 && gpuBytes == 1;
  const std::string what = vol + " in one " + t.format + " " + std::to_string(g.width()) + "x" +
                           std::to_string(g.height()) + " texture (mosaic, " +
                           std::to_string(g.tilesX) + "x" + std::to_string(g.tilesY) + " tiles, " +
                           formatBytes(t.bytes) + (quantised ? ", quantised to 8 bits" : "") + ")";
  if (limits.textureBudget != 0 && t.bytes > limits.textureBudget) {
    plan.reason = what + " exceeds the texture budget " + formatBytes(limits.textureBudget) +
                  " of " + limits.profile;
  } else if (limits.textureUnits < 1) {
    plan.reason = "no texture unit left for the volume on " + limits.profile;
  } else {
    plan.fits = true;
    plan.reason = what;
  }
  return plan;
}

std::unique_ptr<MosaicLayout> MosaicLayout::create(const Volume& volume,
                                                   const gpu::DeviceLimits& limits,
                                                   gpu::MemoryLedger& ledger) {
  std::unique_ptr<MosaicLayout> l(new MosaicLayout());
  l->voxels_ = &volume;
  l->plan_ = planFor(volume, limits);
  if (!l->plan_.fits) throw GpuError("mosaic layout: " + l->plan_.reason);
  l->geometry_ = geometryFor(volume.dims(), limits.max2DTextureSize);
  l->storage_ = storageFor(volume.type(), limits);
  l->mapping_ = normalisedMapping(volume);
  const Geometry& g = l->geometry_;
  const gpu::TexelFormat f = formatOf(l->storage_);
  l->texture_ =
      gpu::Texture::create2D(ledger, std::string("volume (mosaic ") + gpu::texelFormatName(f) + ")",
                             f, g.width(), g.height());
  // Slice by slice, so the host needs one slice of staging, not the whole
  // mosaic; the unused tiles of the last row get zeros (glTexImage2D with
  // no data leaves them undefined).
  const std::size_t rowStride = static_cast<std::size_t>(g.dims.x) * gpu::uploadBytesPerTexel(f);
  const std::size_t sliceBytes = rowStride * static_cast<std::size_t>(g.dims.y);
  HostBudget::global().check(sliceBytes, "mosaic upload staging");
  std::vector<std::uint8_t> staging(sliceBytes);
  for (int z = 0; z < g.tilesX * g.tilesY; ++z) {
    if (z < g.dims.z) {
      packSlice(volume, z, l->storage_, staging.data(), rowStride);
    } else if (z == g.dims.z) {
      std::fill(staging.begin(), staging.end(), std::uint8_t{0});
    }
    const glm::ivec2 origin = g.addressOf(0, 0, z);
    l->texture_.updateRegion({origin, 0}, {g.dims.x, g.dims.y, 1}, staging.data());
  }
  gpu::checkErrors("mosaic layout: uploading " + std::to_string(g.width()) + "x" +
                   std::to_string(g.height()) + " " + gpu::texelFormatName(f));
  return l;
}

gpu::ShaderPart MosaicLayout::glsl() const {
  return gpu::embeddedShaderPart("layout/mosaic.glsl");
}

int MosaicLayout::bind(const gpu::Program& program, int firstUnit) const {
  texture_.bind(firstUnit);
  program.set("u_layoutMosaic", firstUnit);
  program.set("u_layoutDims", glm::vec3(geometry_.dims));
  program.set("u_layoutTilesX", static_cast<float>(geometry_.tilesX));
  program.set("u_layoutInvSize", glm::vec2(1.0f / static_cast<float>(geometry_.width()),
                                           1.0f / static_cast<float>(geometry_.height())));
  return 1;
}

LayoutEntry MosaicLayout::registration() {
  return {
      .name = "mosaic",
      .plan = [](const Volume& shape, const gpu::DeviceLimits& limits,
                 int) { return planFor(shape, limits); },
      .create = [](const Volume& volume, const gpu::DeviceLimits& limits, gpu::MemoryLedger& ledger,
                   int) -> std::unique_ptr<Layout> { return create(volume, limits, ledger); }};
}

}  // namespace tessera::layout
