#pragma once
// The checks every layout that stores its volume in one 3D texture makes
// against a device (texture3d, fcc): ES 3, the largest 3D texture, the
// texture budget and a free unit, in that order, each refusal saying why.
#include <algorithm>
#include <cstdint>
#include <string>

#include <glm/vec3.hpp>

#include "tessera/core/HostBudget.h"
#include "tessera/gpu/DeviceProfile.h"

namespace tessera::layout {

// Empty when a `dims` texture of `bytes` fits; otherwise the plan's reason.
// `what` describes the texture, `noEs3` is the reason without ES 3, and
// `contents` names what would take the texture unit.
inline std::string refusalFor3DTexture(const gpu::DeviceLimits& limits, glm::ivec3 dims,
                                       std::uint64_t bytes, const std::string& what,
                                       const std::string& noEs3, const std::string& contents) {
  if (limits.api != gpu::ApiLevel::Gles3 || limits.max3DTextureSize == 0) return noEs3;
  if (std::max({dims.x, dims.y, dims.z}) > limits.max3DTextureSize) {
    return what + " exceeds the max 3D texture size " + std::to_string(limits.max3DTextureSize) +
           " of " + limits.profile;
  }
  if (limits.textureBudget != 0 && bytes > limits.textureBudget) {
    return what + " exceeds the texture budget " + formatBytes(limits.textureBudget) + " of " +
           limits.profile;
  }
  if (limits.textureUnits < 1)
    return "no texture unit left for " + contents + " on " + limits.profile;
  return {};
}

}  // namespace tessera::layout
