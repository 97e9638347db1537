#include "tessera/gpu/DeviceSession.h"

#include "tessera/core/HostBudget.h"

namespace tessera::gpu {

DeviceLimits applyProfile(const DeviceProfile& profile, GlContext& context) {
  if (profile.hostBudget != 0 && profile.hostBudget < HostBudget::global().limitBytes()) {
    HostBudget::global().setLimit(profile.hostBudget);
  }
  const DeviceLimits limits = effectiveLimits(profile, context.caps());
  context.ledger().setBudget(limits.textureBudget);
  return limits;
}

DeviceSession openDevice(const std::string& profileNameOrFile) {
  DeviceSession s;
  s.profile = DeviceProfile::find(profileNameOrFile);
  GlContext::Options options;
  options.api = s.profile.api;
  s.context = GlContext::createHeadless(options);
  s.limits = applyProfile(s.profile, *s.context);
  return s;
}

DeviceSession borrowDevice(GlContext& context, const DeviceProfile& profile) {
  DeviceSession s;
  s.profile = profile;
  s.context = std::shared_ptr<GlContext>(&context, [](GlContext*) {});  // not ours to destroy
  s.limits = applyProfile(s.profile, context);
  return s;
}

}  // namespace tessera::gpu
