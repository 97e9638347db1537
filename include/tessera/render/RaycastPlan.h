#pragma once
// How the ray caster will store a volume on a device at an image size: the
// layout plan plus the ray caster's own share of units and bytes.
#include <cstdint>
#include <string>

#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/layout/Planner.h"

namespace tessera::render {

struct RaycastPlan {
  layout::Plan plan;
  std::uint64_t reservedBytes = 0;  // TF table, empty-space grid, render target, buffers
  int skipBlock = 0;                // 0 when there are too few units for the grid
  std::string note;                 // e.g. why skipping was turned off
};

// GPU bytes the ray caster needs besides the volume.
std::uint64_t raycasterReservedBytes(glm::ivec3 dims, int width, int height, int skipBlock);

// With fewer than 3 texture units the empty-space grid is dropped, so that
// one unit stays for the volume (the TF takes the other).
RaycastPlan planRaycast(const gpu::DeviceLimits& limits, const Volume& volume,
                        const std::string& layout, int width, int height, int skipBlock);

}  // namespace tessera::render
