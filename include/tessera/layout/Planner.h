#pragma once
// The planner: given a volume, a device's limits and the user's wishes,
// choose how the volume lives in textures — the first registered layout
// (layout/LayoutRegistry.h: texture3d, mosaic, packed-mosaic) whose cost fits
// the device, else downsample by 2 along the axes that need it — and say why
// in one line (DESIGN.md, Layouts). It never fails with "maximum texture
// size exceeded". layout/VolumeUpload.h runs plan -> reduce -> create.
#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/MemoryLedger.h"
#include "tessera/layout/Layout.h"

namespace tessera::layout {

struct PlanRequest {
  std::string layout = "auto";  // auto, or a registered layout's name
  // Texture units and GPU bytes the technique needs besides the volume
  // (the ray caster: its TF table and empty-space grid, the render target).
  int reservedUnits = 2;
  std::uint64_t reservedBytes = 0;
  // The voxels are not in host memory (a streamed source): an in-core layout
  // must also fit them in the device's host budget, else bricks stream them.
  bool streamed = false;
};

struct Plan {
  LayoutPlan layout;                 // the chosen layout (layout.fits is true)
  glm::ivec3 downsample{1};          // factors to apply to the volume first
  glm::ivec3 volumeDims{0};          // dims after downsampling
  std::vector<LayoutPlan> rejected;  // alternatives tried first, with why not
  std::string reason;                // one line a human can read
  int volumeUnits = 0;               // texture units left for the volume
  bool downsampled() const { return downsample != glm::ivec3(1); }
};

// Throws InputError for an unknown layout name, or when the wish can never
// be met (texture3d on a device without 3D textures, no unit left).
Plan planLayout(const Volume& volume, const gpu::DeviceLimits& limits, const PlanRequest& request);

// Creates and uploads the planned layout. `volume` must already be
// downsampled by plan.downsample (see lod::downsample).
std::unique_ptr<Layout> createLayout(const Plan& plan, const Volume& volume,
                                     const gpu::DeviceLimits& limits, gpu::MemoryLedger& ledger);

}  // namespace tessera::layout
