// libFuzzer target: gpu::DeviceProfile::fromJson, and the promise that
// toJson() of an accepted profile reads back to an equal profile.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "FuzzSupport.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/DeviceProfile.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  tessera::fuzz::initialize();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto profile = tessera::gpu::DeviceProfile::fromJson(text, "fuzz");
    const auto again = tessera::gpu::DeviceProfile::fromJson(profile.toJson(), "fuzz round trip");
    if (!(again == profile)) {
      std::fprintf(stderr, "toJson/fromJson round trip changed the profile:\n%s\n%s\n",
                   profile.toJson().c_str(), again.toJson().c_str());
      std::abort();
    }
  } catch (const tessera::Error& e) {
    tessera::fuzz::rejected(e);
  }
  return 0;
}
