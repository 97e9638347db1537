#include "tessera/render/RaycastPlan.h"

#include <glm/vec3.hpp>

#include "tessera/render/Raycaster.h"

namespace tessera::render {

std::uint64_t raycasterReservedBytes(glm::ivec3 dims, int width, int height, int skipBlock) {
  const std::uint64_t target =
      static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) * 4;
  const std::uint64_t lut = 4096 * 8;
  std::uint64_t blocks = 0;
  if (skipBlock > 0) {
    const glm::u64vec3 c =
        (glm::u64vec3(dims) + glm::u64vec3(skipBlock - 1)) / glm::u64vec3(skipBlock);
    // At most RGBA8 per block (ES 2), plus the slack of the grid mosaic's last row.
    blocks = c.x * c.y * c.z * 4 + c.x * c.y * 4 * 64;
  }
  return target + lut + blocks + 4096;  // + vertex buffers
}

RaycastPlan planRaycast(const gpu::DeviceLimits& limits, const Volume& volume,
                        const std::string& layout, int width, int height, int skipBlock) {
  RaycastPlan rp;
  rp.skipBlock = skipBlock;
  if (skipBlock > 0 && limits.textureUnits < Raycaster::kOwnTextureUnits + 1) {
    rp.skipBlock = 0;
    rp.note = "empty-space skipping off: " + limits.profile + " has " +
              std::to_string(limits.textureUnits) + " texture units";
  }
  layout::PlanRequest wish;
  wish.layout = layout;
  wish.reservedUnits = rp.skipBlock > 0 ? Raycaster::kOwnTextureUnits : 1;
  rp.reservedBytes = raycasterReservedBytes(volume.dims(), width, height, rp.skipBlock);
  wish.reservedBytes = rp.reservedBytes;
  rp.plan = layout::planLayout(volume, limits, wish);
  return rp;
}

}  // namespace tessera::render
