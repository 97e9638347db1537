#include "tessera/layout/VolumeUpload.h"

#include "tessera/core/Error.h"
#include "tessera/layout/LayoutRegistry.h"
#include "tessera/lod/InCoreMultiresSource.h"

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
  request.streamed = source.multires() != nullptr;
  upload.plan = planLayout(source.shape(), limits, request);
  const LayoutEntry& entry = LayoutRegistry::global().find(upload.plan.layout.layout);
  if (entry.streamsBricks) {
    // Streamed: the technique sees the shape only; in core: the volume
    // itself (for references), bricked from a pyramid built here.
    std::shared_ptr<const lod::MultiresSource> pyramid = source.multires();
    if (pyramid) {
      upload.volume = std::make_shared<Volume>(source.shape());
    } else {
      upload.volume = source.level(glm::ivec3(1));
      pyramid = std::make_shared<lod::InCoreMultiresSource>(upload.volume);
    }
    gpu::DeviceLimits volumeLimits = limits;
    volumeLimits.textureUnits = upload.plan.volumeUnits;
    if (limits.textureBudget != 0) volumeLimits.textureBudget -= technique.bytes;
    if (!entry.stream) throw Error("layout " + entry.name + " streams bricks but cannot stream");
    upload.layout = entry.stream(pyramid, volumeLimits, context.ledger());
    upload.pyramid = std::move(pyramid);
    // The plan made from the shape alone did not know the source's chunks
    // (which set the brick size) nor its levels: report what was built.
    const std::string planned = upload.plan.layout.reason;
    upload.plan.layout = upload.layout->plan();
    if (upload.plan.reason.rfind(planned, 0) == 0) {
      upload.plan.reason = upload.plan.layout.reason + upload.plan.reason.substr(planned.size());
    }
    return upload;
  }
  upload.volume = source.level(upload.plan.downsample);
  upload.layout = createLayout(upload.plan, *upload.volume, limits, context.ledger());
  return upload;
}

}  // namespace tessera::layout
