#pragma once
// A device profile applied to this process: the host budget, an OpenGL ES
// context of the profile's API level, the effective limits and the GPU
// ledger's budget — everything "render as if on that device" needs.
#include <memory>
#include <string>

#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/GlContext.h"

namespace tessera::render {

struct DeviceSession {
  gpu::DeviceProfile profile;
  std::unique_ptr<gpu::GlContext> context;
  gpu::DeviceLimits limits;
};

// Lowers HostBudget::global() to the profile's host budget (never raises it).
DeviceSession openDevice(const std::string& profileNameOrFile);

}  // namespace tessera::render
