// The overlay in the slice views (session/Fusion.h fuseSliceImage): the same
// pixel -> voxel mapping as sliceImage (core/SliceImage.h), then the fused
// volume's colour at that voxel's centre, by world coordinates.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/common.hpp>

#include "tessera/core/Error.h"
#include "tessera/session/Fusion.h"

namespace tessera::session {

void fuseSliceImage(Image& image, const Volume& anatomy, const SliceFrame& f, int index,
                    const Overlay& overlay) {
  if (!overlay.fused || !overlay.fused->volume) return;
  const FusedVolume& fused = *overlay.fused;
  const glm::ivec3 dims = anatomy.dims();
  const glm::dvec3 spacing = anatomy.spacing();
  const SliceRaster raster = sliceRaster(f, dims, spacing);
  if (image.width() != raster.width || image.height() != raster.height) {
    throw InputError("overlay in a slice view: the image is " + std::to_string(image.width()) +
                     "x" + std::to_string(image.height()) + ", the slice " +
                     std::to_string(raster.width) + "x" + std::to_string(raster.height));
  }
  const glm::dmat4 toFused = fusedFromAnatomy(anatomy, *fused.volume);
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

}  // namespace tessera::session
