#pragma once
// The one way a volume gets onto a device for a technique: plan (which
// layout and which reduction fit the device's limits next to what the
// technique reserves), reduce (the source's level at the plan's factors),
// create the layout (upload). The CLI, the viewers and the benchmarks all
// call uploadVolume; render/TechniqueRegistry.h's createTechnique calls it
// with the technique's requirements.
#include <cstdint>
#include <memory>
#include <string>

#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/layout/Layout.h"
#include "tessera/layout/Planner.h"
#include "tessera/lod/VolumeSource.h"

namespace tessera::layout {

// What the technique that renders the volume needs of the device besides it.
struct Reservation {
  int textureUnits = 2;
  std::uint64_t bytes = 0;
  // false: the technique keeps its own copy of the voxels (slice2d's slice
  // stacks); nothing is planned or uploaded, and the volume is the source's
  // full resolution.
  bool samplesLayout = true;
};

struct VolumeUpload {
  Plan plan;
  // The voxels the layout holds (the source's level at plan.downsample): the
  // source's own volume at full resolution, else a reduction owned here.
  std::shared_ptr<Volume> volume;
  std::unique_ptr<Layout> layout;  // null when the technique stores the volume itself
  // A layout that streams: the pyramid it reads (the source's own, or one
  // built here from the in-core volume); the CPU reference reads its levels.
  std::shared_ptr<const lod::MultiresSource> pyramid;
};

// `layoutWish`: "auto" or a registered layout's name. Throws InputError for
// a wish the device cannot meet, BudgetError when the textures do not fit
// the ledger's budget (next to what is already allocated).
VolumeUpload uploadVolume(gpu::GlContext& context, const gpu::DeviceLimits& limits,
                          const lod::VolumeSource& source, const Reservation& technique,
                          const std::string& layoutWish = "auto");

}  // namespace tessera::layout
