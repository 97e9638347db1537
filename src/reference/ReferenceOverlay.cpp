#include "tessera/reference/ReferenceOverlay.h"

#include "tessera/core/Error.h"
#include "tessera/reference/ReferenceRaycaster.h"

namespace tessera {

Image renderReferenceWithLines(const Volume& volume, const TransferFunction& tf,
                               const Camera& camera, const RenderSettings& settings, int width,
                               int height, const Image& lineColor,
                               const std::vector<float>& lineDistance, int threads) {
  if (width <= 0 || height <= 0) throw InputError("reference: image size must be positive");
  sampleDistance(settings, volume.spacing());  // the step's invariant
  if (lineColor.width() != width || lineColor.height() != height ||
      lineDistance.size() != static_cast<std::size_t>(width) * height) {
    throw InputError("reference overlay: line layer is " + std::to_string(lineColor.width()) + "x" +
                     std::to_string(lineColor.height()) + " with " +
                     std::to_string(lineDistance.size()) + " distances, image is " +
                     std::to_string(width) + "x" + std::to_string(height));
  }
  if (settings.mode != RenderMode::Composite) {
    throw InputError("reference overlay: only composite mode attenuates lines");
  }
  const ReferenceStops stops{lineColor, lineDistance};
  return renderReference(volume, tf, camera, settings, width, height, threads, nullptr, &stops);
}

}  // namespace tessera
