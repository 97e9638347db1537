#include "tessera/render/ClippingUniforms.h"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec4.hpp>

#include "tessera/core/Error.h"

namespace tessera::render {

void addClippingDefines(const RenderSettings& settings, std::vector<std::string>& defines) {
  if (settings.clipping.active()) defines.push_back("CLIPPING 1");
}

void checkClipping(const Clipping& clipping) {
  if (clipping.planes.size() > static_cast<std::size_t>(kMaxClipPlanes)) {
    throw InputError("at most " + std::to_string(kMaxClipPlanes) + " clip planes, got " +
                     std::to_string(clipping.planes.size()));
  }
  for (const ClipPlane& c : clipping.planes) {
    const double len = glm::length(c.normal);
    if (!(len > 1e-12) || !std::isfinite(len) || !std::isfinite(c.distance)) {
      throw InputError("a clip plane needs a finite non-zero normal and a finite distance");
    }
  }
  for (int a = 0; a < 3; ++a) {
    const double lo = clipping.cropMin[a], hi = clipping.cropMax[a];
    if (!(lo >= 0.0 && hi <= 1.0 && lo < hi)) {
      throw InputError("crop box along " + std::string(1, "xyz"[a]) + ": " + std::to_string(lo) +
                       ":" + std::to_string(hi) + " must satisfy 0 <= min < max <= 1");
    }
  }
}

void setClippingUniforms(const gpu::Program& program, const RenderSettings& settings,
                         const Camera& camera, glm::dvec3 extent) {
  if (!settings.clipping.active()) return;
  checkClipping(settings.clipping);
  const std::vector<glm::dvec4> h =
      clipHalfSpaces(settings.clipping, camera.modelFromWorld, extent);
  for (int i = 0; i < kMaxClipPlanes; ++i) {
    const std::string name = "u_clipPlanes[" + std::to_string(i) + "]";
    program.set(name.c_str(), i < static_cast<int>(h.size())
                                  ? glm::vec4(h[static_cast<std::size_t>(i)])
                                  : glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  }
  program.set("u_cropMin", glm::vec3(settings.clipping.cropMin));
  program.set("u_cropMax", glm::vec3(settings.clipping.cropMax));
}

}  // namespace tessera::render
