#include "tessera/core/RenderSettings.h"

#include <string>

#include "tessera/core/Error.h"

namespace tessera {

std::string renderModeChoices() {
  const auto names = renderModeNames();
  std::string text;
  for (std::size_t i = 0; i < names.size(); ++i) {
    text += i == 0 ? "" : i + 1 == names.size() ? " or " : ", ";
    text += names[i];
  }
  return text;
}

double sampleDistance(const RenderSettings& settings, glm::dvec3 spacing) {
  if (!(settings.stepVoxels > 0.0) || !std::isfinite(settings.stepVoxels)) {
    throw InputError("step must be a positive number of voxels, got " +
                     std::to_string(settings.stepVoxels));
  }
  return settings.stepVoxels * std::min({spacing.x, spacing.y, spacing.z});
}

}  // namespace tessera
