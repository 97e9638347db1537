#include "tessera/layout/LayoutRegistry.h"

#include "tessera/core/Error.h"
#include "tessera/layout/BricksLayout.h"
#include "tessera/layout/FccLayout.h"
#include "tessera/layout/MosaicLayout.h"
#include "tessera/layout/PackedMosaicLayout.h"
#include "tessera/layout/Texture3DLayout.h"

namespace tessera::layout {

bool LayoutEntry::runsOn(const gpu::DeviceLimits& limits) const {
  if (minApi == gpu::ApiLevel::Gles3 && limits.api != gpu::ApiLevel::Gles3) return false;
  return !needs3DTextures || (limits.api == gpu::ApiLevel::Gles3 && limits.max3DTextureSize > 0);
}

LayoutRegistry& LayoutRegistry::global() {
  static LayoutRegistry registry = [] {
    LayoutRegistry r;
    r.add(Texture3DLayout::registration());
    r.add(MosaicLayout::registration());
    r.add(PackedMosaicLayout::registration());
    // Last: chosen only when the volume fits no in-core layout.
    r.add(BricksLayout::registration());
    r.add(FccLayout::registration(lattice::FccDensity::Same));
    r.add(FccLayout::registration(lattice::FccDensity::Half));
    return r;
  }();
  return registry;
}

}  // namespace tessera::layout
