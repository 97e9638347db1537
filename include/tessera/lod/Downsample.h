#pragma once
// Box-filter downsampling of a volume by integer factors per axis (the first
// step of the LOD pyramid; DESIGN.md, Large data).
#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"

namespace tessera::lod {

// Each output voxel is the mean of the factor.x * factor.y * factor.z input
// voxels it covers (fewer at the far edges when a dimension is not a
// multiple of the factor: dims_out = ceil(dims / factor)). Spacing grows by
// the factor, so the world extent is preserved up to the padded edge; the
// scalar type and the window are kept. Factors must be >= 1.
Volume downsample(const Volume& volume, glm::ivec3 factor);

}  // namespace tessera::lod
