#pragma once
// Going from the overview of a large volume to its native resolution
// (Schultz 2016 §4.2, §7.3-7.4), the part both front ends share: the
// crosshair linking the slice views and the 3D view, the bread-slice region
// (a box picked in a slice view, read at native resolution with one bounded
// read of the source, never a whole level), the grid view's block around
// the current grid point, and the overlay lines that mark the region or
// block and the crosshair in the overview.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "tessera/core/Camera.h"
#include "tessera/core/Volume.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/lod/GridNavigator.h"
#include "tessera/lod/MultiresSource.h"
#include "tessera/render/Overlay.h"
#include "tessera/viewer/SliceView.h"

namespace tessera::viewer {

// The region's default side: 256 voxels (the paper's custom sub-volume), or
// less so that side^3 voxels of `bytesPerVoxel` fit `budgetBytes`; at least 16.
int defaultRegionSide(std::uint64_t budgetBytes, int bytesPerVoxel);

// The overview (the 3D view's whole volume): the finest level of the
// pyramid with at most this many voxels (half the profile's texture budget,
// at most 64 Mi), so that a store is never read whole at native resolution.
std::uint64_t overviewVoxelBudget(const gpu::DeviceLimits& limits);
// What a native region or grid block may take: a quarter of the texture
// budget, and no more than one 3D texture of the profile holds (so that it
// is shown at native resolution, not reduced by the planner).
std::uint64_t regionBudgetBytes(const gpu::DeviceLimits& limits);

// A box of `side` voxels per axis centred on `centre`, shifted to lie inside
// `dims` and clamped to it where the volume is smaller.
lod::VoxelBox regionAround(glm::ivec3 centre, glm::ivec3 side, glm::ivec3 dims);

// Lines of a level-0 voxel box (corners at voxel boundaries) in the model
// frame of a volume of `dims` voxels and `extent` (the frame the viewer's
// bounding box is drawn in: centred at the origin, axes along the index axes).
std::vector<render::OverlayLine> boxLines(const lod::VoxelBox& box, glm::ivec3 dims,
                                          glm::dvec3 extent, glm::vec4 colour);
// Three lines through the centre of `voxel`, each across the whole volume
// along one index axis: the crosshair of the slice views, in 3D.
std::vector<render::OverlayLine> crosshairLines(glm::ivec3 voxel, glm::ivec3 dims,
                                                glm::dvec3 extent, glm::vec4 colour);

// Where a level-0 box (nullopt: the whole volume) of a volume of `dims`
// voxels and `spacing` sits in the whole volume's model frame (its centre,
// mm from the volume's centre) and the radius a camera frames it with.
struct BoxFraming {
  glm::dvec3 centre{0.0};
  double radius = 1.0;
};
BoxFraming boxFraming(const std::optional<lod::VoxelBox>& box, glm::ivec3 dims, glm::dvec3 spacing);

// The camera for the 3D view after its volume changes from box `from` to box
// `to` of the same volume (overview <-> native sub-volume), framed for `to`
// (radius set as Camera::frame does): the view direction kept, the target
// moved by the boxes' offset and the zoom scaled by their radii, so that
// every point of the patient stays where it was on screen (a swap changes
// the data, not the view).
Camera cameraAcrossSwap(const Camera& before, const std::optional<lod::VoxelBox>& from,
                        const std::optional<lod::VoxelBox>& to, glm::ivec3 dims,
                        glm::dvec3 spacing);

// The grid view's grid over `dims` whose 2x2x2 block has at most
// `blockVoxels` voxels, its cells on brick boundaries (what an Explorer
// makes from its region budget).
lod::GridNavigator gridForBudget(glm::ivec3 dims, std::uint64_t blockVoxels);

class Explorer {
 public:
  // `regionBudgetBytes`: what a native region or grid block may take (the
  // profile's texture budget, or a share of it).
  Explorer(std::shared_ptr<const lod::MultiresSource> source, std::uint64_t regionBudgetBytes);

  const lod::MultiresSource& source() const { return *source_; }
  glm::ivec3 dims() const { return dims_; }  // level 0

  // The crosshair: a level-0 voxel, clamped into the volume.
  glm::ivec3 crosshair() const { return crosshair_; }
  void setCrosshair(glm::ivec3 voxel);

  // The finest level whose whole volume has at most `maxVoxels` voxels (the
  // coarsest if none does).
  int overviewLevel(std::uint64_t maxVoxels) const;
  // The whole level as one volume, with the full volume's world geometry.
  Volume readLevel(int level) const;

  // Bread-slice region: side per axis (default defaultRegionSide of the
  // budget), clamped to the volume.
  int regionSide() const { return regionSide_; }
  void setRegionSide(int side);
  int maxRegionSide() const { return maxRegionSide_; }
  lod::VoxelBox regionAt(glm::ivec3 centre) const;
  // The region a user marks in a slice view of level 0: a click (pixels a
  // and b equal) picks the default cube around the voxel; a drag picks the
  // voxels under the rectangle in the slice's plane (each side at most
  // maxRegionSide) and regionSide across it, centred on slice `index`.
  lod::VoxelBox regionFromSlice(const SliceGeometry& slice, glm::ivec2 a, glm::ivec2 b,
                                int index) const;
  // Reads `box` of level 0: exactly box.count() voxels from the source. The
  // volume keeps the full volume's direction and sits where the box sits in
  // the patient frame. InputError for an empty box or one outside the volume.
  Volume readRegion(const lod::VoxelBox& box) const;

  // Grid view over level 0, cells sized so that a 2x2x2 block fits the budget.
  lod::GridNavigator& grid() { return grid_; }
  const lod::GridNavigator& grid() const { return grid_; }

 private:
  std::shared_ptr<const lod::MultiresSource> source_;
  glm::ivec3 dims_;
  int bytesPerVoxel_ = 1;
  int maxRegionSide_ = 256;
  int regionSide_ = 256;
  glm::ivec3 crosshair_{0};
  lod::GridNavigator grid_;
};

}  // namespace tessera::viewer
