#pragma once
// A device profile applied to this process and an OpenGL ES context: the host
// budget, a context of the profile's API level, the effective limits and the
// GPU ledger's budget — everything "render as if on that device" needs. The
// CLI opens a headless session; the viewers apply the profile to the context
// their window or canvas made, so `tessera view --profile` obeys the same
// limits as `tessera render --profile`.
#include <memory>
#include <string>

#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/GlContext.h"

namespace tessera::gpu {

struct DeviceSession {
  DeviceProfile profile;
  // Owned (openDevice), or the caller's (borrowDevice: a window's or a
  // canvas's context, which outlives the session).
  std::shared_ptr<GlContext> context;
  DeviceLimits limits;
};

// Applies `profile` to `context`: lowers HostBudget::global() to the
// profile's host budget (never raises it), sets the context's ledger budget
// to the effective texture budget, and returns the effective limits
// (min(profile, caps); see effectiveLimits).
DeviceLimits applyProfile(const DeviceProfile& profile, GlContext& context);

// A headless context of the profile's API level with the profile applied.
DeviceSession openDevice(const std::string& profileNameOrFile);

// The caller's current context (a window's, the page's WebGL) with `profile`
// applied; the session refers to it and does not own it.
DeviceSession borrowDevice(GlContext& context, const DeviceProfile& profile);

}  // namespace tessera::gpu
