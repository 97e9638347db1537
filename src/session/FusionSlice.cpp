// The overlay in the slice views (session/Fusion.h fuseSliceImage): the same
// pixel -> voxel mapping as sliceImage (core/SliceImage.h) and the slice
// views of a pyramid's level (viewer/SliceView.h), then the fused volume's
// colour at that voxel's centre, by world coordinates.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/common.hpp>

#include "tessera/core/Error.h"
#include "tessera/session/Fusion.h"

namespace tessera::session {

namespace {

// Slice `index` of a grid of `dims` voxels of `spacing` whose normalised
// coordinates p (voxel centres at (i + 0.5) / dims) go to the fused
// volume's by `toFused`.
void fuseSliceGrid(Image& image, glm::ivec3 dims, glm::dvec3 spacing, const SliceFrame& f,
                   int index, const glm::dmat4& toFused, const FusedVolume& fused) {
  const SliceRaster raster = sliceRaster(f, dims, spacing);
  if (image.width() != raster.width || image.height() != raster.height) {
    throw InputError("overlay in a slice view: the image is " + std::to_string(image.width()) +
                     "x" + std::to_string(image.height()) + ", the slice " +
                     std::to_string(raster.width) + "x" + std::to_string(raster.height));
  }
  if (index < 0 || index >= dims[f.axis]) {
    throw InputError("overlay in a slice view: slice " + std::to_string(index) +
                     " is outside 0:" + std::to_string(dims[f.axis]));
  }
  const glm::dvec3 d(dims);
  for (int row = 0; row < raster.height; ++row) {
    const int vr =
        sliceVoxelOf(row, raster.pixelMm, spacing[f.rowAxis], dims[f.rowAxis], f.rowReversed);
    for (int col = 0; col < raster.width; ++col) {
      glm::ivec3 v(0);
      v[f.axis] = index;
      v[f.colAxis] =
          sliceVoxelOf(col, raster.pixelMm, spacing[f.colAxis], dims[f.colAxis], f.colReversed);
      v[f.rowAxis] = vr;
      const glm::dvec3 p = (glm::dvec3(v) + 0.5) / d;
      const glm::dvec4 c = fusedColorAt(fused, glm::dvec3(toFused * glm::dvec4(p, 1.0)));
      const double w = std::clamp(c.a, 0.0, 1.0);
      if (w <= 0.0) continue;
      std::uint8_t* px = image.pixel(col, row);
      for (int k = 0; k < 3; ++k) {
        const double mixed = (1.0 - w) * (px[k] / 255.0) + w * std::clamp(c[k], 0.0, 1.0);
        px[k] = static_cast<std::uint8_t>(std::lround(mixed * 255.0));
      }
    }
  }
}

}  // namespace

void fuseSliceImage(Image& image, const Volume& anatomy, const SliceFrame& f, int index,
                    const Overlay& overlay) {
  if (!overlay.fused || !overlay.fused->volume) return;
  const FusedVolume& fused = *overlay.fused;
  fuseSliceGrid(image, anatomy.dims(), anatomy.spacing(), f, index,
                fusedFromAnatomy(anatomy, *fused.volume), fused);
}

// A level's normalised coordinates are level 0's: every level spans the
// same box (levels need not halve), so level 0's affine places them.
void fuseSliceImage(Image& image, const lod::MultiresSource& anatomy, int level,
                    const SliceFrame& f, int index, const Overlay& overlay) {
  if (!overlay.fused || !overlay.fused->volume) return;
  if (level < 0 || level >= anatomy.levelCount()) {
    throw InputError("overlay in a slice view: level " + std::to_string(level) +
                     " is outside 0:" + std::to_string(anatomy.levelCount()));
  }
  const FusedVolume& fused = *overlay.fused;
  const lod::LevelInfo li = anatomy.levelInfo(level);
  fuseSliceGrid(image, li.dims, glm::dvec3(li.spacing), f, index,
                fusedFromAnatomy(anatomy.shape(), *fused.volume), fused);
}

}  // namespace tessera::session
