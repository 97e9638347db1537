#include "tessera/viewer/SliceView.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"

namespace tessera::viewer {

namespace {

// The nearest world axis (0 R-L, 1 A-P, 2 S-I) of a direction.
int dominantWorldAxis(const glm::dvec3& d) {
  int w = 0;
  for (int a = 1; a < 3; ++a) {
    if (std::abs(d[a]) > std::abs(d[w])) w = a;
  }
  return w;
}

}  // namespace

SliceFrame sliceFrame(const glm::dmat3& direction, int axis) {
  if (axis < 0 || axis > 2) throw InputError("slice axis must be 0, 1 or 2 (x, y or z)");
  const glm::dmat3 frame = nearestOrthonormal(direction);
  SliceFrame f;
  f.axis = axis;
  // World (RAS) directions of the image's right and up, as radiologists
  // read each plane (the same rules as `tessera slice`).
  glm::dvec3 screenRight, screenUp;
  const int normal = dominantWorldAxis(frame[axis]);
  if (normal == 2) {
    f.plane = "axial";
    screenRight = {-1, 0, 0};
    screenUp = {0, 1, 0};
  } else if (normal == 1) {
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
  const double sc = spacing_[frame_.colAxis], sr = spacing_[frame_.rowAxis];
  pixelMm_ = std::min(sc, sr);
  size_.x = std::max(1, static_cast<int>(std::lround(dims_[frame_.colAxis] * sc / pixelMm_)));
  size_.y = std::max(1, static_cast<int>(std::lround(dims_[frame_.rowAxis] * sr / pixelMm_)));
}

int SliceGeometry::voxelAlong(int pixel, int a, bool reversed) const {
  const int n = dims_[a];
  const int t =
      std::clamp(static_cast<int>(std::floor((pixel + 0.5) * pixelMm_ / spacing_[a])), 0, n - 1);
  return reversed ? n - 1 - t : t;
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
  Image image(size_.x, size_.y);
  const double width = window.max - window.min;
  for (int row = 0; row < size_.y; ++row) {
    for (int col = 0; col < size_.x; ++col) {
      glm::ivec3 v = voxelAt({col, row}, 0);
      const double value = slab.finiteValueAtIndex(slab.index(v.x, v.y, v.z));
      const double n = width > 0.0 ? std::clamp((value - window.min) / width, 0.0, 1.0) : 0.0;
      const glm::dvec3 rgb = tf ? tf->color(n) : glm::dvec3(n);
      std::uint8_t* px = image.pixel(col, row);
      for (int c = 0; c < 3; ++c) {
        px[c] = static_cast<std::uint8_t>(std::lround(std::clamp(rgb[c], 0.0, 1.0) * 255.0));
      }
      px[3] = 255;
    }
  }
  return image;
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
