#include "tessera/core/RenderSettings.h"

#include <string>

#include "tessera/core/Error.h"

namespace tessera {

double sampleDistance(const RenderSettings& settings, glm::dvec3 spacing) {
  if (!(settings.stepVoxels > 0.0) || !std::isfinite(settings.stepVoxels)) {
    throw InputError("step must be a positive number of voxels, got " +
                     std::to_string(settings.stepVoxels));
  }
  return settings.stepVoxels * std::min({spacing.x, spacing.y, spacing.z});
}

}  // namespace tessera
