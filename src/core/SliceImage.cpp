#include "tessera/core/SliceImage.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"

namespace tessera {

SliceFrame sliceFrame(const glm::dmat3& direction, int axis) {
  if (axis < 0 || axis > 2) {
    throw InputError("slice axis " + std::to_string(axis) + ": expected 0, 1 or 2 (x, y or z)");
  }
  const glm::dmat3 frame = nearestOrthonormal(direction);
  const glm::dvec3 normal = frame[axis];
  int dominant = 0;
  for (int w = 1; w < 3; ++w) {
    if (std::abs(normal[w]) > std::abs(normal[dominant])) dominant = w;
  }
  SliceFrame f;
  f.axis = axis;
  glm::dvec3 screenRight, screenUp;  // world (RAS) directions of image right and up
  if (dominant == 2) {
    f.plane = "axial";
    screenRight = {-1, 0, 0};
    screenUp = {0, 1, 0};
  } else if (dominant == 1) {
    f.plane = "coronal";
    screenRight = {-1, 0, 0};
    screenUp = {0, 0, 1};
  } else {
    f.plane = "sagittal";
    screenRight = {0, -1, 0};
    screenUp = {0, 0, 1};
  }
  const int p = (axis + 1) % 3, q = (axis + 2) % 3;
  const bool pHorizontal =
      std::abs(glm::dot(frame[p], screenRight)) >= std::abs(glm::dot(frame[q], screenRight));
  f.colAxis = pHorizontal ? p : q;
  f.rowAxis = pHorizontal ? q : p;
  f.colReversed = glm::dot(frame[f.colAxis], screenRight) < 0.0;
  // Rows grow downwards: the index grows downwards unless it points up.
  f.rowReversed = glm::dot(frame[f.rowAxis], screenUp) > 0.0;
  const glm::dvec3 right = frame[f.colAxis] * (f.colReversed ? -1.0 : 1.0);
  const glm::dvec3 down = frame[f.rowAxis] * (f.rowReversed ? -1.0 : 1.0);
  f.right = directionLabel(right);
  f.left = directionLabel(-right);
  f.bottom = directionLabel(down);
  f.top = directionLabel(-down);
  return f;
}

SliceRaster sliceRaster(const SliceFrame& f, glm::ivec3 dims, glm::dvec3 spacing) {
  SliceRaster r;
  r.pixelMm = std::min(spacing[f.colAxis], spacing[f.rowAxis]);
  r.width =
      std::max(1, static_cast<int>(std::lround(dims[f.colAxis] * spacing[f.colAxis] / r.pixelMm)));
  r.height =
      std::max(1, static_cast<int>(std::lround(dims[f.rowAxis] * spacing[f.rowAxis] / r.pixelMm)));
  return r;
}

int sliceVoxelOf(int pixel, double pixelMm, double spacing, int n, bool reversed) {
  const int t =
      std::clamp(static_cast<int>(std::floor((pixel + 0.5) * pixelMm / spacing)), 0, n - 1);
  return reversed ? n - 1 - t : t;
}

Image sliceImage(const Volume& volume, const SliceFrame& f, int index, ValueRange window,
                 const TransferFunction* colour) {
  const glm::ivec3 dims = volume.dims();
  if (index < 0 || index >= dims[f.axis]) {
    throw InputError("slice index " + std::to_string(index) + " is outside 0.." +
                     std::to_string(dims[f.axis] - 1) + " along axis " + "xyz"[f.axis]);
  }
  const glm::dvec3 spacing = volume.spacing();
  const SliceRaster raster = sliceRaster(f, dims, spacing);
  const int nc = dims[f.colAxis], nr = dims[f.rowAxis];
  Image image(raster.width, raster.height);
  for (int row = 0; row < raster.height; ++row) {
    const int vr = sliceVoxelOf(row, raster.pixelMm, spacing[f.rowAxis], nr, f.rowReversed);
    for (int col = 0; col < raster.width; ++col) {
      glm::ivec3 v(0);
      v[f.axis] = index;
      v[f.colAxis] = sliceVoxelOf(col, raster.pixelMm, spacing[f.colAxis], nc, f.colReversed);
      v[f.rowAxis] = vr;
      const double value = volume.finiteValueAtIndex(volume.index(v.x, v.y, v.z));
      const double n = window.max > window.min
                           ? std::clamp((value - window.min) / (window.max - window.min), 0.0, 1.0)
                           : 0.0;
      const glm::dvec3 rgb = colour ? colour->color(n) : glm::dvec3(n);
      std::uint8_t* px = image.pixel(col, row);
      for (int c = 0; c < 3; ++c) {
        px[c] = static_cast<std::uint8_t>(std::lround(std::clamp(rgb[c], 0.0, 1.0) * 255.0));
      }
      px[3] = 255;
    }
  }
  return image;
}

}  // namespace tessera
