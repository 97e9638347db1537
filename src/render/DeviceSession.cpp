#include "tessera/render/DeviceSession.h"

#include "tessera/core/HostBudget.h"

namespace tessera::render {

DeviceSession openDevice(const std::string& profileNameOrFile) {
  DeviceSession s;
  s.profile = gpu::DeviceProfile::find(profileNameOrFile);
  if (s.profile.hostBudget != 0 && s.profile.hostBudget < HostBudget::global().limitBytes()) {
    HostBudget::global().setLimit(s.profile.hostBudget);
  }
  gpu::GlContext::Options options;
  options.api = s.profile.api;
  s.context = gpu::GlContext::createHeadless(options);
  s.limits = gpu::effectiveLimits(s.profile, s.context->caps());
  s.context->ledger().setBudget(s.limits.textureBudget);
  return s;
}

}  // namespace tessera::render
