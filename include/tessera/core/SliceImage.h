#pragma once
// One index-axis slice of a volume as a 2D image: nearest voxel
// at voxel centres, no interpolation, in the radiological convention with
// the patient directions of its four edges. `tessera slice` and the web
// page's slice views both draw slices with this, so they show the same
// pixels and the same letters for the same file.
//
// Radiological convention, whatever the storage order: axial and coronal
// slices have the patient's left on the image's right (as if facing the
// patient; axial seen from the feet), anterior up (axial) or superior up
// (coronal); sagittal slices have anterior on the image's left and superior
// up. The plane is named by the world axis nearest to the slice normal.
#include <string>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "tessera/core/Image.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/core/Volume.h"

namespace tessera {

// How a slice's two in-plane index axes land on the image.
struct SliceFrame {
  int axis = 2;                          // index axis the slice is normal to
  std::string plane;                     // axial, coronal or sagittal
  int colAxis = 0;                       // index axis along image columns (left to right)
  int rowAxis = 1;                       // index axis along image rows (top to bottom)
  bool colReversed = false;              // column 0 shows the last voxel of colAxis
  bool rowReversed = false;              // row 0 shows the last voxel of rowAxis
  std::string left, right, top, bottom;  // patient directions of the edges
};

// The frame of slices normal to index `axis` (0, 1, 2) of a volume whose
// index axes have the world (RAS) directions `direction` (columns).
SliceFrame sliceFrame(const glm::dmat3& direction, int axis);

// The image's size in square pixels of the finer in-plane spacing.
struct SliceRaster {
  int width = 1;
  int height = 1;
  double pixelMm = 1.0;
};
SliceRaster sliceRaster(const SliceFrame& frame, glm::ivec3 dims, glm::dvec3 spacing);

// Pixel -> voxel along one image axis: pixels of `pixelMm` over `n` voxels
// of `spacing`, nearest voxel centre, optionally reversed.
int sliceVoxelOf(int pixel, double pixelMm, double spacing, int n, bool reversed);

// Slice `index` (along frame.axis) of `volume` through `window`: grey, or
// the colour of `colour` (a TF's colour only; null: grey). InputError when
// the index lies outside the volume.
Image sliceImage(const Volume& volume, const SliceFrame& frame, int index, ValueRange window,
                 const TransferFunction* colour = nullptr);

}  // namespace tessera
