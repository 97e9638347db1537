#pragma once
// A generated multiresolution volume of any size that never exists whole:
// readBox computes the voxels of the box asked for, at any level, so a
// 1024^3 volume costs only the bricks a view reads. Used for the large-volume
// acceptance runs and tests without a chunked store on disk.
//
// The field ("head"): a noise-textured ellipsoidal head in u8 — a bright
// shell (skull), soft tissue with a value-noise texture, and small bright
// speckles (vessels) that only the finest levels resolve. Every level point-
// samples the same continuous field at its voxel centres (level-l voxel i
// sits at level-0 coordinate (i + 0.5) 2^l), so levels agree where the field
// is smooth; it is not a mean pyramid (that would need 8^l evaluations per
// coarse voxel).
#include <string>

#include "tessera/lod/MultiresSource.h"

namespace tessera::lod {

class ProceduralMultiresSource final : public MultiresSource {
 public:
  // "head:WxHxD" (or "head:N" for a cube); "head16:..." the same head in
  // u16 (the 8-bit field times 257 plus a texture finer than one 8-bit
  // step). InputError on anything else.
  static bool isSpec(const std::string& spec);
  explicit ProceduralMultiresSource(const std::string& spec, int coarsestSide = 16);

  const Volume& shape() const override { return shape_; }
  int levelCount() const override { return static_cast<int>(dims_.size()); }
  LevelInfo levelInfo(int level) const override;
  Volume readBox(int level, const VoxelBox& box) const override;
  std::string describe() const override { return spec_; }

  // The field at level-0 continuous voxel coordinate x (voxel centres at
  // i + 0.5), 0 .. 255.
  double valueAt(glm::dvec3 x) const;
  // The head16: field, 0 .. 65535.
  double value16At(glm::dvec3 x) const;

 private:
  std::string spec_;
  Volume shape_;
  std::vector<glm::ivec3> dims_;
  bool sixteen_ = false;
};

}  // namespace tessera::lod
