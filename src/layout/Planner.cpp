#include "tessera/layout/Planner.h"

#include <algorithm>
#include <cmath>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/layout/LayoutRegistry.h"

namespace tessera::layout {

namespace {

std::string dimsText(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

// "layout texture3d needs 3D textures, which ipad2 does not have (use
// mosaic or packed-mosaic)". Only layouts of the same kind are offered: one
// that "auto" may not pick (fcc: it changes the reconstruction) is not
// replaced by a Cartesian layout behind the user's back, and the other way
// round.
std::string unmetNeeds(const LayoutEntry& entry, const gpu::DeviceLimits& limits) {
  const std::string need = !entry.needsText.empty() ? entry.needsText
                           : entry.needs3DTextures  ? "3D textures"
                                                    : "OpenGL ES 3";
  std::vector<std::string> others;
  for (const LayoutEntry& e : LayoutRegistry::global().entries()) {
    if (e.automatic == entry.automatic && e.runsOn(limits)) others.push_back(e.name);
  }
  std::string use;
  for (std::size_t i = 0; i < others.size(); ++i) {
    use += (i == 0 ? " (use " : i + 1 == others.size() ? " or " : ", ") + others[i];
  }
  if (!use.empty()) use += ")";
  if (others.empty() && !entry.automatic) {
    use =
        " (no layout of this kind runs there; without it the volume is rendered on its "
        "Cartesian grid)";
  }
  return "layout " + entry.name + " needs " + need + ", which " + limits.profile +
         " does not have" + use;
}

// Which axes to halve when nothing fits: those longer than the largest
// texture side the candidate layouts allow; otherwise (the volume has too
// many voxels for the textures or the budget) the longest axis, so the
// voxels stay as close to isotropic as they were.
glm::ivec3 axesToHalve(glm::ivec3 dims, const gpu::DeviceLimits& limits, bool only3d) {
  const int side = only3d ? limits.max3DTextureSize : limits.max2DTextureSize;
  glm::ivec3 halve(0);
  for (int a = 0; a < (only3d ? 3 : 2); ++a) halve[a] = dims[a] > side ? 1 : 0;
  if (halve == glm::ivec3(0)) {
    const int longest = std::max({dims.x, dims.y, dims.z});
    for (int a = 0; a < 3; ++a) {
      if (dims[a] == longest) {
        halve[a] = 1;
        break;
      }
    }
  }
  return halve;
}

}  // namespace

Plan planLayout(const Volume& volume, const gpu::DeviceLimits& limits, const PlanRequest& request) {
  std::vector<const LayoutEntry*> candidates;
  if (request.layout == "auto") {
    // Bricks only for streamed sources: an in-core volume that fits no layout
    // is downsampled, because only a front end that drives the bricks'
    // per-frame streaming (tessera render, bench) refines them (--layout bricks).
    for (const LayoutEntry& e : LayoutRegistry::global().entries()) {
      if (e.automatic && (!e.streamsBricks || request.streamed)) candidates.push_back(&e);
    }
  } else {
    const LayoutEntry& wished = LayoutRegistry::global().find(request.layout);
    if (!wished.runsOn(limits)) throw InputError(unmetNeeds(wished, limits));
    candidates.push_back(&wished);
  }
  const int units = limits.textureUnits - request.reservedUnits;
  if (units < 1) {
    throw InputError(limits.profile + " has " + std::to_string(limits.textureUnits) +
                     " texture units and the technique needs " +
                     std::to_string(request.reservedUnits) + ": none is left for the volume");
  }
  gpu::DeviceLimits volumeLimits = limits;
  volumeLimits.textureUnits = units;
  if (limits.textureBudget != 0) {
    if (request.reservedBytes >= limits.textureBudget) {
      throw InputError("the renderer's own textures (" + formatBytes(request.reservedBytes) +
                       ") exceed the texture budget of " + limits.profile + " (" +
                       formatBytes(limits.textureBudget) + ")");
    }
    volumeLimits.textureBudget = limits.textureBudget - request.reservedBytes;
  }

  Plan plan;
  plan.volumeUnits = units;
  glm::ivec3 dims = volume.dims();
  for (int round = 0; round < 64; ++round) {
    Volume shape = Volume::shapeOnly(dims, volume.type());
    const ValueRange range = volume.valueRange();  // what a layout says of how it stores values
    if (std::isfinite(range.min) && std::isfinite(range.max) && range.min <= range.max) {
      shape.setValueRange(range);
    }
    for (const LayoutEntry* candidate : candidates) {
      LayoutPlan p = candidate->plan(shape, volumeLimits, units);
      const std::uint64_t hostBytes = shape.voxelCount() * bytesPerVoxel(shape.type());
      if (p.fits && request.streamed && !candidate->streamsBricks && limits.hostBudget != 0 &&
          hostBytes > limits.hostBudget) {
        p.fits = false;
        p.reason = dimsText(dims) + " needs " + formatBytes(hostBytes) +
                   " of host memory in core, over the host budget " +
                   formatBytes(limits.hostBudget) + " of " + limits.profile;
      }
      if (p.fits) {
        plan.layout = std::move(p);
        plan.volumeDims = dims;
        std::string why = plan.layout.reason;
        if (plan.downsampled()) {
          why = dimsText(volume.dims()) + " does not fit " + limits.profile +
                " under any layout; downsampled by " + dimsText(plan.downsample) + " to " + why;
        } else if (request.layout == "auto") {
          for (const LayoutPlan& r : plan.rejected) why += "; not " + r.layout + ": " + r.reason;
        }
        plan.reason = why;
        return plan;
      }
      if (round == 0) plan.rejected.push_back(std::move(p));
    }
    if (dims == glm::ivec3(1)) break;
    const bool only3d = std::all_of(candidates.begin(), candidates.end(),
                                    [](const LayoutEntry* e) { return e->needs3DTextures; });
    const glm::ivec3 halve = axesToHalve(dims, volumeLimits, only3d);
    for (int a = 0; a < 3; ++a) {
      if (halve[a] && dims[a] > 1) {
        dims[a] = (dims[a] + 1) / 2;
        plan.downsample[a] *= 2;
      }
    }
  }
  throw InputError(dimsText(volume.dims()) + " cannot be stored on " + limits.profile +
                   " even downsampled to a single voxel");
}

std::unique_ptr<Layout> createLayout(const Plan& plan, const Volume& volume,
                                     const gpu::DeviceLimits& limits, gpu::MemoryLedger& ledger) {
  if (volume.dims() != plan.volumeDims) {
    throw Error("createLayout: volume is " + dimsText(volume.dims()) + ", the plan is for " +
                dimsText(plan.volumeDims));
  }
  gpu::DeviceLimits volumeLimits = limits;
  volumeLimits.textureUnits = plan.volumeUnits;
  return LayoutRegistry::global()
      .find(plan.layout.layout)
      .create(volume, volumeLimits, ledger, plan.volumeUnits);
}

}  // namespace tessera::layout
