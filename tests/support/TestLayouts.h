#pragma once
// The layouts image tests render through, taken from the layout registry, so
// that a layout registered anywhere (a library file or a test's static
// initialiser) is tested without editing the tests.
#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/layout/LayoutRegistry.h"
#include "tessera/layout/MosaicLayout.h"
#include "tessera/layout/PackedMosaicLayout.h"
#include "tessera/layout/Texture3DLayout.h"

namespace tessera::test {

struct LayoutChoice {
  // Tried first for each layout: a 2D texture size small enough that a
  // layout able to split the volume over several textures and channels does
  // (its seams then fall inside the image); a layout that cannot fit within
  // it gets the context's own limits. 0: the context's limits only.
  int squeezed2DTextureSize = 128;
  // Texture units a layout may use.
  int units = 6;
};

// The layouts the registry offers on `c` that sample the trilinear field of
// `v`'s own voxels from memory the layout holds (holdsVoxelGrid, not
// streamsBricks), each created over `v`, in registration order: those the
// CPU reference of `v` renders as their twin (texture3d on ES 3 only, mosaic,
// packed-mosaic, and any registered later).
inline std::vector<std::unique_ptr<layout::Layout>> layoutsFor(gpu::GlContext& c, const Volume& v,
                                                               LayoutChoice choice = {}) {
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  gpu::DeviceLimits squeezed = limits;
  if (choice.squeezed2DTextureSize > 0) {
    squeezed.max2DTextureSize = std::min(limits.max2DTextureSize, choice.squeezed2DTextureSize);
  }
  std::vector<std::unique_ptr<layout::Layout>> layouts;
  for (const layout::LayoutEntry& e : layout::LayoutRegistry::global().entries()) {
    if (!e.holdsVoxelGrid || e.streamsBricks || !e.runsOn(limits)) continue;
    const bool fitsSqueezed = e.plan(v, squeezed, choice.units).fits;
    layouts.push_back(e.create(v, fitsSqueezed ? squeezed : limits, c.ledger(), choice.units));
  }
  return layouts;
}

// The three grid layouts by name, not from the registry: texture3d (ES 3
// only), mosaic, and packed-mosaic with 6 units in 2D textures of at most
// `packed2DSize`, so that its seams fall inside the image.
inline std::vector<std::unique_ptr<layout::Layout>> gridLayouts(gpu::GlContext& c,
                                                                gpu::ApiLevel api, const Volume& v,
                                                                int packed2DSize) {
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  gpu::DeviceLimits packedLimits = limits;
  packedLimits.max2DTextureSize = packed2DSize;
  std::vector<std::unique_ptr<layout::Layout>> layouts;
  if (api == gpu::ApiLevel::Gles3) {
    layouts.push_back(layout::Texture3DLayout::create(v, limits, c.ledger()));
  }
  layouts.push_back(layout::MosaicLayout::create(v, limits, c.ledger()));
  layouts.push_back(layout::PackedMosaicLayout::create(v, packedLimits, c.ledger(), 6));
  return layouts;
}

// The registry's names of those layouts, for messages.
inline std::string layoutNames(const std::vector<std::unique_ptr<layout::Layout>>& layouts) {
  std::string names;
  for (const auto& l : layouts) names += (names.empty() ? "" : ", ") + l->name();
  return names;
}

}  // namespace tessera::test
