#include "tessera/viewer/SliceView.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"

namespace tessera::viewer {

int axisForPlane(const glm::dmat3& direction, const std::string& plane) {
  const int world = plane == "sagittal" ? 0 : plane == "coronal" ? 1 : plane == "axial" ? 2 : -1;
  if (world < 0) throw InputError("plane '" + plane + "': expected axial, coronal or sagittal");
  const glm::dmat3 frame = nearestOrthonormal(direction);
  int best = 0;
  for (int a = 1; a < 3; ++a) {
    if (std::abs(frame[a][world]) > std::abs(frame[best][world])) best = a;
  }
  return best;
}

SliceGeometry::SliceGeometry(glm::ivec3 dims, glm::dvec3 spacing, const glm::dmat3& direction,
                             int axis)
    : dims_(dims), spacing_(spacing), frame_(sliceFrame(direction, axis)) {
  for (int a = 0; a < 3; ++a) {
    if (dims[a] < 1 || !(spacing[a] > 0.0)) {
      throw InputError(
          "slice view: the volume needs at least one voxel and a positive spacing "
          "along every axis");
    }
  }
  const SliceRaster raster = sliceRaster(frame_, dims_, spacing_);
  pixelMm_ = raster.pixelMm;
  size_ = {raster.width, raster.height};
}

int SliceGeometry::voxelAlong(int pixel, int a, bool reversed) const {
  return sliceVoxelOf(pixel, pixelMm_, spacing_[a], dims_[a], reversed);
}

glm::ivec3 SliceGeometry::voxelAt(glm::ivec2 pixel, int index) const {
  glm::ivec3 v(0);
  v[frame_.axis] = index;
  v[frame_.colAxis] = voxelAlong(pixel.x, frame_.colAxis, frame_.colReversed);
  v[frame_.rowAxis] = voxelAlong(pixel.y, frame_.rowAxis, frame_.rowReversed);
  return v;
}

glm::dvec2 SliceGeometry::pointOf(glm::ivec3 voxel) const {
  auto along = [&](int a, bool reversed) {
    const int t = reversed ? dims_[a] - 1 - voxel[a] : voxel[a];
    return (t + 0.5) * spacing_[a] / pixelMm_;
  };
  return {along(frame_.colAxis, frame_.colReversed), along(frame_.rowAxis, frame_.rowReversed)};
}

glm::ivec2 SliceGeometry::pixelOf(glm::ivec3 voxel) const {
  const glm::dvec2 p = pointOf(voxel);
  return {std::clamp(static_cast<int>(std::floor(p.x)), 0, size_.x - 1),
          std::clamp(static_cast<int>(std::floor(p.y)), 0, size_.y - 1)};
}

lod::VoxelBox SliceGeometry::voxelsUnder(glm::ivec2 a, glm::ivec2 b, int index) const {
  const glm::ivec3 va = voxelAt(glm::clamp(a, glm::ivec2(0), size_ - 1), index);
  const glm::ivec3 vb = voxelAt(glm::clamp(b, glm::ivec2(0), size_ - 1), index);
  return {glm::min(va, vb), glm::max(va, vb) + 1};
}

Image SliceGeometry::render(const lod::MultiresSource& source, int level, int index,
                            ValueRange window, const TransferFunction* tf) const {
  const lod::LevelInfo info = source.levelInfo(level);
  if (info.dims != dims_) {
    throw InputError("slice view: level " + std::to_string(level) +
                     " does not have the dims this view was made for");
  }
  if (index < 0 || index >= dims_[frame_.axis]) {
    throw InputError("slice index " + std::to_string(index) + " is outside 0.." +
                     std::to_string(dims_[frame_.axis] - 1));
  }
  lod::VoxelBox box{glm::ivec3(0), dims_};
  box.begin[frame_.axis] = index;
  box.end[frame_.axis] = index + 1;
  return renderSlab(source.readBox(level, box), window, tf);
}

Image SliceGeometry::renderSlab(const Volume& slab, ValueRange window,
                                const TransferFunction* tf) const {
  glm::ivec3 expected = dims_;
  expected[frame_.axis] = 1;
  if (slab.dims() != expected) throw InputError("slice view: slab of the wrong size");
  return sliceImage(slab, frame_, 0, window, tf);
}

SliceViewport SliceViewport::fit(glm::ivec2 imageSize, glm::dvec2 rectOrigin, glm::dvec2 rectSize) {
  SliceViewport v;
  v.imageSize = glm::max(imageSize, glm::ivec2(1));
  v.scale = std::max(1e-9, std::min(rectSize.x / v.imageSize.x, rectSize.y / v.imageSize.y));
  v.origin = rectOrigin + 0.5 * (rectSize - glm::dvec2(v.imageSize) * v.scale);
  return v;
}

glm::ivec2 SliceViewport::pixelAt(glm::dvec2 screen) const {
  const glm::dvec2 p = glm::floor(toImage(screen));
  return glm::clamp(glm::ivec2(p), glm::ivec2(0), imageSize - 1);
}

bool SliceViewport::contains(glm::dvec2 screen) const {
  const glm::dvec2 p = toImage(screen);
  return p.x >= 0.0 && p.y >= 0.0 && p.x < imageSize.x && p.y < imageSize.y;
}

}  // namespace tessera::viewer
