#pragma once
// Where the voxels a layout uploads come from: the first of the three seams
// (DESIGN.md: volume source -> layout -> technique). The planner needs only
// the volume's shape; the upload then asks for the voxels at the reduction
// the plan chose. In-core volumes (lod/InCoreVolumeSource.h) are the only
// source today; a bricked multiresolution source (bricks of each pyramid
// level on disk or over HTTP) implements the same two calls.
#include <memory>

#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"
#include "tessera/lod/MultiresSource.h"

namespace tessera::lod {

class VolumeSource {
 public:
  virtual ~VolumeSource() = default;

  // The full-resolution volume's shape: dims, scalar type, geometry
  // (spacing, direction, origin), value range and window. Whether it also
  // holds voxels is the source's business; callers read only its shape.
  virtual const Volume& shape() const = 0;

  // The voxels reduced by `factor` along each axis ((1,1,1): as stored):
  // dims = ceil(dims / factor), each voxel the mean of those it covers, the
  // world box and window kept (lod::downsample). The result may be shared:
  // an in-core source hands out its own volume at (1,1,1), so a change of
  // its window shows in both.
  virtual std::shared_ptr<Volume> level(glm::ivec3 factor) const = 0;

  // The same volume as a pyramid read box by box, when it is not held in
  // host memory (lod/MultiresVolumeSource.h); null for in-core sources. The
  // planner then counts the host memory an in-core layout would need, and
  // the bricks layout streams from it.
  virtual std::shared_ptr<const MultiresSource> multires() const { return nullptr; }
};

}  // namespace tessera::lod
