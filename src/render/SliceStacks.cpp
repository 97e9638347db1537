#include "tessera/render/SliceStacks.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "tessera/core/Error.h"

namespace tessera::render {

namespace {

int nextPowerOfTwo(int v) {
  int p = 1;
  while (p < v) p *= 2;
  return p;
}

}  // namespace

std::string SliceAtlasPlan::describe() const {
  return std::to_string(atlases) + " x " + std::to_string(atlasSize.x) + "x" +
         std::to_string(atlasSize.y) + " (" + std::to_string(columns) + "x" + std::to_string(rows) +
         " tiles of " + std::to_string(tile.x) + "x" + std::to_string(tile.y) + ")";
}

glm::ivec2 sliceTileAxes(int axis) {
  return axis == 0 ? glm::ivec2(1, 2) : axis == 1 ? glm::ivec2(0, 2) : glm::ivec2(0, 1);
}

SliceAtlasPlan planSliceAtlas(glm::ivec3 dims, int axis, int maxTextureSize, bool powerOfTwo) {
  if (axis < 0 || axis > 2) throw InputError("slice stack axis must be 0, 1 or 2");
  const glm::ivec2 a = sliceTileAxes(axis);
  SliceAtlasPlan p;
  p.axis = axis;
  p.tile = {dims[a.x], dims[a.y]};
  p.slices = dims[axis];
  if (p.tile.x > maxTextureSize || p.tile.y > maxTextureSize) {
    throw GpuError("a " + std::to_string(p.tile.x) + "x" + std::to_string(p.tile.y) +
                   " slice does not fit a " + std::to_string(maxTextureSize) +
                   " texture; downsample the volume (tessera convert --downsample)");
  }
  if (powerOfTwo) {
    int p2 = 1;
    while (p2 * 2 <= maxTextureSize) p2 *= 2;
    maxTextureSize = p2;
  }
  const int capacity = (maxTextureSize / p.tile.x) * (maxTextureSize / p.tile.y);
  p.atlases = (p.slices + capacity - 1) / capacity;
  p.tilesPerAtlas = (p.slices + p.atlases - 1) / p.atlases;
  // Moser & Weiskopf: the best width x height that holds every slice.
  std::uint64_t bestArea = std::numeric_limits<std::uint64_t>::max();
  int bestSkew = std::numeric_limits<int>::max();
  for (int cols = 1; cols <= p.tilesPerAtlas && cols * p.tile.x <= maxTextureSize; ++cols) {
    const int rows = (p.tilesPerAtlas + cols - 1) / cols;
    int w = cols * p.tile.x, h = rows * p.tile.y;
    if (powerOfTwo) {
      w = nextPowerOfTwo(w);
      h = nextPowerOfTwo(h);
    }
    if (w > maxTextureSize || h > maxTextureSize) continue;
    const std::uint64_t area = static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h);
    const int skew = std::abs(w - h);
    if (area < bestArea || (area == bestArea && skew < bestSkew)) {
      bestArea = area;
      bestSkew = skew;
      p.columns = cols;
      p.rows = rows;
      p.atlasSize = {w, h};
    }
  }
  if (p.columns == 0) {
    throw GpuError("slice stack " + std::to_string(axis) + " does not fit " +
                   std::to_string(maxTextureSize) + " textures");
  }
  return p;
}

SliceStacks::SliceStacks(const Volume& volume) : dims_(volume.dims()) {
  const std::size_t n = volume.voxelCount();
  indices_.resize(n);
  const ValueRange w = volume.window();
  const double scale = w.max > w.min ? 1.0 / (w.max - w.min) : 0.0;
  if (volume.type() == ScalarType::U8) {
    // 256 raw values: one table instead of a division per voxel.
    std::uint8_t table[256];
    for (int v = 0; v < 256; ++v) {
      table[v] =
          static_cast<std::uint8_t>(std::lround(std::clamp((v - w.min) * scale, 0.0, 1.0) * 255.0));
    }
    const std::uint8_t* src = volume.dataAs<std::uint8_t>();
    for (std::size_t i = 0; i < n; ++i) indices_[i] = table[src[i]];
    return;
  }
  for (std::size_t i = 0; i < n; ++i) {
    indices_[i] = static_cast<std::uint8_t>(
        std::lround(std::clamp((volume.finiteValueAtIndex(i) - w.min) * scale, 0.0, 1.0) * 255.0));
  }
}

void SliceStacks::fillAtlas(const SliceAtlasPlan& plan, int atlas, const std::uint8_t* palette,
                            std::vector<std::uint8_t>& out) const {
  fillAtlasRows(plan, atlas, 0, plan.atlasSize.y, palette, out);
}

void SliceStacks::fillAtlasBand(const SliceAtlasPlan& plan, int atlas, int band,
                                const std::uint8_t* palette, std::vector<std::uint8_t>& out) const {
  const int y0 = band * plan.tile.y;
  fillAtlasRows(plan, atlas, y0, y0 + plan.bandRows(band), palette, out);
}

void SliceStacks::fillShadingAtlasBand(const SliceAtlasPlan& plan, int atlas, int band,
                                       std::vector<std::uint8_t>& out) const {
  const int y0 = band * plan.tile.y;
  const int y1 = y0 + plan.bandRows(band);
  const std::size_t rowBytes = static_cast<std::size_t>(plan.atlasSize.x) * 4;
  out.assign(rowBytes * static_cast<std::size_t>(y1 - y0), 0);
  const int first = atlas * plan.tilesPerAtlas;
  const int last = std::min(plan.slices, first + plan.tilesPerAtlas);
  const std::size_t stride[3] = {1, static_cast<std::size_t>(dims_.x),
                                 static_cast<std::size_t>(dims_.x) * dims_.y};
  const glm::ivec2 a = sliceTileAxes(plan.axis);
  const std::size_t du = stride[a.x], dv = stride[a.y], di = stride[plan.axis];
  for (int s = first; s < last; ++s) {
    const glm::ivec2 o = plan.tileOrigin(s);
    const std::size_t below = static_cast<std::size_t>(std::max(s - 1, 0)) * di;
    const std::size_t here = static_cast<std::size_t>(s) * di;
    const std::size_t above = static_cast<std::size_t>(std::min(s + 1, plan.slices - 1)) * di;
    const int v0 = std::max(0, y0 - o.y), v1 = std::min(plan.tile.y, y1 - o.y);
    for (int v = v0; v < v1; ++v) {
      std::uint8_t* row = out.data() + static_cast<std::size_t>(o.y + v - y0) * rowBytes +
                          static_cast<std::size_t>(o.x) * 4;
      for (int u = 0; u < plan.tile.x; ++u) {
        const std::size_t i = static_cast<std::size_t>(u) * du + static_cast<std::size_t>(v) * dv;
        row[u * 4] = indices_[here + i];
        row[u * 4 + 1] = indices_[below + i];
        row[u * 4 + 2] = indices_[above + i];
        row[u * 4 + 3] = 255;
      }
    }
  }
}

void SliceStacks::fillAtlasRows(const SliceAtlasPlan& plan, int atlas, int y0, int y1,
                                const std::uint8_t* palette, std::vector<std::uint8_t>& out) const {
  const int texelBytes = palette ? 4 : 1;
  const std::size_t rowBytes = static_cast<std::size_t>(plan.atlasSize.x) * texelBytes;
  out.assign(rowBytes * static_cast<std::size_t>(y1 - y0), 0);
  const int first = atlas * plan.tilesPerAtlas;
  const int last = std::min(plan.slices, first + plan.tilesPerAtlas);
  const std::size_t sx = 1, sy = static_cast<std::size_t>(dims_.x),
                    sz = static_cast<std::size_t>(dims_.x) * dims_.y;
  const std::size_t stride[3] = {sx, sy, sz};
  const glm::ivec2 a = sliceTileAxes(plan.axis);
  const std::size_t du = stride[a.x], dv = stride[a.y], di = stride[plan.axis];
  for (int s = first; s < last; ++s) {
    const glm::ivec2 o = plan.tileOrigin(s);
    const int v0 = std::max(0, y0 - o.y), v1 = std::min(plan.tile.y, y1 - o.y);
    for (int v = v0; v < v1; ++v) {
      std::uint8_t* row = out.data() + static_cast<std::size_t>(o.y + v - y0) * rowBytes +
                          static_cast<std::size_t>(o.x) * texelBytes;
      const std::uint8_t* src = indices_.data() + s * di + v * dv;
      if (palette == nullptr) {
        if (du == 1) {
          std::memcpy(row, src, static_cast<std::size_t>(plan.tile.x));
        } else {
          for (int u = 0; u < plan.tile.x; ++u) row[u] = src[u * du];
        }
      } else {
        for (int u = 0; u < plan.tile.x; ++u) {
          std::memcpy(row + static_cast<std::size_t>(u) * 4, palette + src[u * du] * 4u, 4);
        }
      }
    }
  }
}

}  // namespace tessera::render
