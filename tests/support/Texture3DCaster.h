#pragma once
// A ray caster over a texture3d layout of a volume, showing `tf`: the plain
// ES 3 set-up the technique tests start from.
#include <memory>

#include "tessera/core/TransferFunction.h"
#include "tessera/core/Volume.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/render/Raycaster.h"

namespace tessera::test {

struct Texture3DCaster {
  Texture3DCaster(gpu::GlContext& c, const Volume& v, const TransferFunction& tf)
      : layout(layout::Texture3DLayout::create(v, gpu::DeviceLimits::of(c.caps()), c.ledger())),
        caster(c, v, *layout) {
    caster.setTransferFunction(tf);
  }

  std::unique_ptr<layout::Texture3DLayout> layout;  // before the caster, which holds it
  render::Raycaster caster;
};

}  // namespace tessera::test
