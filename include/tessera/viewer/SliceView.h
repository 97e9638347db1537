#pragma once
// The 2D slice views next to the 3D view (Schultz 2016 §7.4's
// "bread slice" flipping): an index-axis slice of a volume at native voxel
// resolution (nearest voxel), in the radiological convention of
// core/SliceImage.h, the one `tessera slice` and the web page draw with
// (tessera::SliceFrame, sliceFrame, sliceVoxelOf, sliceImage). The slice is
// read as a one-voxel-thick box of a lod::MultiresSource level, so a store
// reads only the chunks it touches; this adds the inverse mappings the
// crosshair needs and the fit of the image into a view.
//
// Pixels are square, of the finer in-plane spacing; a voxel covers one or
// more pixels along an axis of coarser spacing. Pixel <-> voxel mappings
// are exact: voxelAt(pixelOf(v)) == v for every voxel of the slice, which
// is what keeps the crosshair linked across the views.
#include <string>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "tessera/core/Image.h"
#include "tessera/core/SliceImage.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/core/Volume.h"
#include "tessera/lod/MultiresSource.h"

namespace tessera::viewer {

// The index axis whose slices are the given plane ("axial", "coronal",
// "sagittal"): the axis nearest the plane's normal (S, A, R).
int axisForPlane(const glm::dmat3& direction, const std::string& plane);

class SliceGeometry {
 public:
  // `dims` and `spacing` of the level shown; `direction` of the volume.
  SliceGeometry(glm::ivec3 dims, glm::dvec3 spacing, const glm::dmat3& direction, int axis);

  const SliceFrame& frame() const { return frame_; }
  int axis() const { return frame_.axis; }
  glm::ivec3 dims() const { return dims_; }
  glm::ivec2 imageSize() const { return size_; }
  double pixelMm() const { return pixelMm_; }

  // The voxel a pixel (column, row from the top) shows; `index` is the slice.
  glm::ivec3 voxelAt(glm::ivec2 pixel, int index) const;
  // The pixel that shows the voxel's centre (the crosshair's pixel).
  glm::ivec2 pixelOf(glm::ivec3 voxel) const;
  // The voxel's centre in continuous image coordinates (pixel centres at
  // i + 0.5): where the crosshair lines go.
  glm::dvec2 pointOf(glm::ivec3 voxel) const;
  // The box of in-plane voxels a rectangle of the image covers, as a voxel
  // range along colAxis and rowAxis (half open); the slice axis gets
  // [index, index + 1).
  lod::VoxelBox voxelsUnder(glm::ivec2 pixelA, glm::ivec2 pixelB, int index) const;

  // The slice `index` read as one box of `level` (nearest voxel): grey over
  // `window` or the TF's colour (tf null: grey). InputError when the index
  // is outside the level.
  Image render(const lod::MultiresSource& source, int level, int index, ValueRange window,
               const TransferFunction* tf) const;
  // The same from a one-voxel-thick slab already read (slab dims = the
  // level's with the slice axis 1).
  Image renderSlab(const Volume& slab, ValueRange window, const TransferFunction* tf) const;

 private:
  int voxelAlong(int pixel, int a, bool reversed) const;
  glm::ivec3 dims_;
  glm::dvec3 spacing_;
  SliceFrame frame_;
  double pixelMm_ = 1.0;
  glm::ivec2 size_{1, 1};
};

// A slice image shown in a screen rectangle, scaled to fit with its aspect
// kept and centred (letterboxed): screen <-> image pixel coordinates.
struct SliceViewport {
  glm::dvec2 origin{0.0};  // screen position of the image's top-left corner
  double scale = 1.0;      // screen units per image pixel
  glm::ivec2 imageSize{1, 1};
  static SliceViewport fit(glm::ivec2 imageSize, glm::dvec2 rectOrigin, glm::dvec2 rectSize);
  glm::dvec2 toImage(glm::dvec2 screen) const { return (screen - origin) / scale; }
  glm::dvec2 toScreen(glm::dvec2 image) const { return origin + image * scale; }
  // The image pixel under a screen point, clamped to the image.
  glm::ivec2 pixelAt(glm::dvec2 screen) const;
  bool contains(glm::dvec2 screen) const;
};

}  // namespace tessera::viewer
