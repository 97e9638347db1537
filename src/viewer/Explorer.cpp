#include "tessera/viewer/Explorer.h"

#include <algorithm>

#include <glm/geometric.hpp>

#include "tessera/core/Error.h"

namespace tessera::viewer {

namespace {

constexpr int kMinRegionSide = 16;
constexpr int kPaperRegionSide = 256;  // Schultz 2016 §7.4: the custom sub-volume
constexpr int kBrickAlign = 32;        // grid cells on brick boundaries

// Level-0 continuous voxel coordinate (corners at integers) -> model frame.
glm::dvec3 toModel(glm::dvec3 voxel, glm::ivec3 dims, glm::dvec3 extent) {
  return (voxel / glm::dvec3(dims) - 0.5) * extent;
}

}  // namespace

std::uint64_t overviewVoxelBudget(const gpu::DeviceLimits& limits) {
  const std::uint64_t budget = limits.textureBudget ? limits.textureBudget / 2 : (1ull << 30);
  return std::min<std::uint64_t>(budget, 64ull << 20);
}

std::uint64_t regionBudgetBytes(const gpu::DeviceLimits& limits) {
  std::uint64_t budget = limits.textureBudget ? limits.textureBudget / 4 : (1ull << 30);
  if (limits.max3DTextureSize > 0) {
    const auto side = static_cast<std::uint64_t>(limits.max3DTextureSize);
    budget = std::min(budget, side * side * side);
  }
  return budget;
}

int defaultRegionSide(std::uint64_t budgetBytes, int bytesPerVoxel) {
  int side = kPaperRegionSide;
  const std::uint64_t per = static_cast<std::uint64_t>(std::max(1, bytesPerVoxel));
  while (side > kMinRegionSide &&
         static_cast<std::uint64_t>(side) * side * side * per > budgetBytes) {
    side -= 16;
  }
  return side;
}

lod::VoxelBox regionAround(glm::ivec3 centre, glm::ivec3 side, glm::ivec3 dims) {
  const glm::ivec3 s = glm::clamp(side, glm::ivec3(1), dims);
  glm::ivec3 begin = centre - s / 2;
  begin = glm::clamp(begin, glm::ivec3(0), dims - s);
  return {begin, begin + s};
}

std::vector<render::OverlayLine> boxLines(const lod::VoxelBox& box, glm::ivec3 dims,
                                          glm::dvec3 extent, glm::vec4 colour) {
  const glm::dvec3 lo = toModel(glm::dvec3(box.begin), dims, extent);
  const glm::dvec3 hi = toModel(glm::dvec3(box.end), dims, extent);
  std::vector<render::OverlayLine> lines;
  render::addBoxEdges(lines, lo, hi, colour);
  return lines;
}

std::vector<render::OverlayLine> crosshairLines(glm::ivec3 voxel, glm::ivec3 dims,
                                                glm::dvec3 extent, glm::vec4 colour) {
  const glm::dvec3 c = glm::dvec3(voxel) + 0.5;
  std::vector<render::OverlayLine> lines;
  for (int axis = 0; axis < 3; ++axis) {
    glm::dvec3 a = c, b = c;
    a[axis] = 0.0;
    b[axis] = dims[axis];
    lines.push_back({toModel(a, dims, extent), toModel(b, dims, extent), colour});
  }
  return lines;
}

BoxFraming boxFraming(const std::optional<lod::VoxelBox>& box, glm::ivec3 dims,
                      glm::dvec3 spacing) {
  const lod::VoxelBox b = box ? *box : lod::VoxelBox{glm::ivec3(0), dims};
  const glm::dvec3 centre = 0.5 * glm::dvec3(b.begin + b.end);
  return {(centre - 0.5 * glm::dvec3(dims)) * spacing,
          0.5 * glm::length(glm::dvec3(b.size()) * spacing)};
}

Camera cameraAcrossSwap(const Camera& before, const std::optional<lod::VoxelBox>& from,
                        const std::optional<lod::VoxelBox>& to, glm::ivec3 dims,
                        glm::dvec3 spacing) {
  const BoxFraming a = boxFraming(from, dims, spacing), b = boxFraming(to, dims, spacing);
  Camera c = before;
  c.radius = b.radius;
  c.target = before.target + a.centre - b.centre;
  // Camera::distance is radius / sin(fov / 2) / zoom: the same distance.
  c.zoom = before.zoom * b.radius / a.radius;
  return c;
}

Explorer::Explorer(std::shared_ptr<const lod::MultiresSource> source,
                   std::uint64_t regionBudgetBytes)
    : source_(std::move(source)),
      dims_(source_->levelInfo(0).dims),
      bytesPerVoxel_(static_cast<int>(bytesPerVoxel(source_->shape().type()))),
      maxRegionSide_(defaultRegionSide(regionBudgetBytes, bytesPerVoxel_)),
      regionSide_(maxRegionSide_),
      crosshair_(dims_ / 2),
      grid_(gridForBudget(
          dims_, regionBudgetBytes / static_cast<std::uint64_t>(std::max(1, bytesPerVoxel_)))) {}

lod::GridNavigator gridForBudget(glm::ivec3 dims, std::uint64_t blockVoxels) {
  return lod::GridNavigator::forBudget(dims, blockVoxels, kBrickAlign);
}

void Explorer::setCrosshair(glm::ivec3 voxel) {
  crosshair_ = glm::clamp(voxel, glm::ivec3(0), dims_ - 1);
}

void Explorer::setRegionSide(int side) {
  regionSide_ = std::clamp(side, kMinRegionSide, maxRegionSide_);
}

int Explorer::overviewLevel(std::uint64_t maxVoxels) const {
  for (int l = 0; l < source_->levelCount(); ++l) {
    if (lod::VoxelBox{glm::ivec3(0), source_->levelInfo(l).dims}.count() <= maxVoxels) return l;
  }
  return source_->levelCount() - 1;
}

Volume Explorer::readLevel(int level) const {
  const lod::LevelInfo info = source_->levelInfo(level);
  Volume v = source_->readBox(level, {glm::ivec3(0), info.dims});
  const Volume& shape = source_->shape();
  v.setDirection(shape.direction());
  v.setSpacing(glm::dvec3(info.spacing));
  // A level covers the same world box: its first voxel centre sits half a
  // level voxel in from the box's corner, which level 0 has at origin - s0/2.
  const glm::dvec3 s0 = shape.spacing(), sl = glm::dvec3(info.spacing);
  v.setOrigin(shape.origin() + shape.direction() * (0.5 * (sl - s0)));
  v.setGeometrySource(shape.geometrySource());
  v.setWindow(shape.window());
  v.setModality(shape.modality());  // the session's default TF follows it
  return v;
}

lod::VoxelBox Explorer::regionAt(glm::ivec3 centre) const {
  return regionAround(centre, glm::ivec3(regionSide_), dims_);
}

lod::VoxelBox Explorer::regionFromSlice(const SliceGeometry& slice, glm::ivec2 a, glm::ivec2 b,
                                        int index) const {
  if (slice.dims() != dims_) throw InputError("region: the slice view is not of level 0");
  if (a == b) return regionAt(slice.voxelAt(a, index));
  const lod::VoxelBox under = slice.voxelsUnder(a, b, index);
  glm::ivec3 side = glm::min(under.size(), glm::ivec3(maxRegionSide_));
  side[slice.axis()] = regionSide_;
  return regionAround((under.begin + under.end) / 2, side, dims_);
}

Volume Explorer::readRegion(const lod::VoxelBox& box) const {
  if (box.count() == 0 || glm::any(glm::lessThan(box.begin, glm::ivec3(0))) ||
      glm::any(glm::greaterThan(box.end, dims_))) {
    throw InputError("region is empty or outside the volume");
  }
  Volume v = source_->readBox(0, box);
  const Volume& shape = source_->shape();
  v.setDirection(shape.direction());
  v.setSpacing(shape.spacing());
  const glm::dvec4 at = shape.indexToWorld() * glm::dvec4(glm::dvec3(box.begin), 1.0);
  v.setOrigin(glm::dvec3(at));
  v.setGeometrySource(shape.geometrySource());
  v.setWindow(shape.window());
  v.setModality(shape.modality());  // the session's default TF follows it
  return v;
}

}  // namespace tessera::viewer
