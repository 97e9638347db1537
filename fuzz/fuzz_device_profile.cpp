// libFuzzer target: gpu::DeviceProfile::fromJson, and the promise that
// toJson() of an accepted profile reads back to an equal profile.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "FuzzTarget.h"
#include "tessera/gpu/DeviceProfile.h"

void tessera::fuzz::fuzzOne(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const auto profile = gpu::DeviceProfile::fromJson(text, "fuzz");
  const auto again = gpu::DeviceProfile::fromJson(profile.toJson(), "fuzz round trip");
  if (!(again == profile)) {
    std::fprintf(stderr, "toJson/fromJson round trip changed the profile:\n%s\n%s\n",
                 profile.toJson().c_str(), again.toJson().c_str());
    std::abort();
  }
}
