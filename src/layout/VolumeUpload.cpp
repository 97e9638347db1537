#include "tessera/layout/VolumeUpload.h"

namespace tessera::layout {

VolumeUpload uploadVolume(gpu::GlContext& context, const gpu::DeviceLimits& limits,
                          const lod::VolumeSource& source, const Reservation& technique,
                          const std::string& layoutWish) {
  VolumeUpload upload;
  if (!technique.samplesLayout) {
    upload.plan.volumeDims = source.shape().dims();
    upload.volume = source.level(glm::ivec3(1));
    return upload;
  }
  PlanRequest request;
  request.layout = layoutWish;
  request.reservedUnits = technique.textureUnits;
  request.reservedBytes = technique.bytes;
  upload.plan = planLayout(source.shape(), limits, request);
  upload.volume = source.level(upload.plan.downsample);
  upload.layout = createLayout(upload.plan, *upload.volume, limits, context.ledger());
  return upload;
}

}  // namespace tessera::layout
