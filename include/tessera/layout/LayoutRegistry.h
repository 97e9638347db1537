#pragma once
// The layouts the planner chooses from (layout/Planner.h). Each layout
// registers what it needs of a device (API level, 3D textures) and what it
// costs (a function that plans its textures for a volume shape within the
// device's limits and a number of texture units), and how it is created.
// The planner holds no list of its own: a new layout (bricks, fcc) plugs in
// by registering, and "auto" tries the layouts in registration order.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tessera/core/NamedRegistry.h"
#include "tessera/core/Volume.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/MemoryLedger.h"
#include "tessera/layout/Layout.h"
#include "tessera/lod/MultiresSource.h"

namespace tessera::layout {

struct LayoutEntry {
  std::string name;
  // What it needs of the device. Asked for by name on a device without it,
  // the planner refuses with an error that names the layouts that would do.
  gpu::ApiLevel minApi = gpu::ApiLevel::Gles2;
  bool needs3DTextures = false;
  // Whether "auto" may choose it; false for a layout that changes the
  // reconstruction (fcc), which must be asked for by name.
  bool automatic = true;
  // What it needs, in words, for the refusal (default: "3D textures" or
  // "OpenGL ES 3" from the two fields above).
  std::string needsText = {};
  // What callers ask of a layout, instead of comparing its name:
  // streamsBricks: it reads the volume brick by brick from a multiresolution
  // source within a budget (a streamed source plans only onto it, and a
  // front end must drive its per-frame refinement: Layout::streaming()).
  bool streamsBricks = false;
  // holdsVoxelGrid: sampleVolume() is the trilinear field of the volume's own
  // voxels, all resident at the planned resolution, so per-voxel data
  // precomputed from them (a gradient texture) matches what it samples. False
  // for a layout that reconstructs another field (fcc) or mixes levels (bricks).
  bool holdsVoxelGrid = true;
  // What it costs: the textures it would allocate for a volume of `shape`
  // within `limits` using at most `units` texture units; fits = false and a
  // reason when it cannot.
  std::function<LayoutPlan(const Volume& shape, const gpu::DeviceLimits& limits, int units)> plan;
  // Creates and uploads it (the volume already reduced to the planned dims).
  std::function<std::unique_ptr<Layout>(const Volume& volume, const gpu::DeviceLimits& limits,
                                        gpu::MemoryLedger& ledger, int units)>
      create;
  // A layout with streamsBricks: creates it over a multiresolution source
  // (planned within `limits`), reading only what the views ask for.
  std::function<std::unique_ptr<Layout>(std::shared_ptr<const lod::MultiresSource> source,
                                        const gpu::DeviceLimits& limits, gpu::MemoryLedger& ledger)>
      stream = {};

  // Whether the device has what the layout needs.
  bool runsOn(const gpu::DeviceLimits& limits) const;
};

// add() a layout after the others (or in place of one of its name); find()
// throws InputError listing choices(): "auto, texture3d, mosaic or ...".
class LayoutRegistry : public NamedRegistry<LayoutEntry> {
 public:
  LayoutRegistry() : NamedRegistry("layout", "auto") {}
  // The built-in layouts, in the planner's order of preference: texture3d,
  // mosaic, packed-mosaic, bricks; then fcc and fcc-half (by name only).
  static LayoutRegistry& global();
};

}  // namespace tessera::layout
