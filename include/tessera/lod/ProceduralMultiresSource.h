#pragma once
// A generated multiresolution volume of any size that never exists whole:
// readBox computes the voxels of the box asked for, at any level, so a
// 1024^3 volume costs only the bricks a view reads. Used for the large-volume
// acceptance runs and tests without a chunked store on disk.
//
// The field ("head"): a noise-textured ellipsoidal head in u8 — a bright
// shell (skull), soft tissue with a value-noise texture, and small bright
// speckles (vessels) that only the finest levels resolve. Level-l voxel i
// sits at level-0 coordinate (i + 0.5) 2^l. head: point-samples the same
// continuous field there at every level. head16: (the scale runs, 512^3 to
// 8192^3, docs/large-data.md "Scale") evaluates levels >= 1 band-limited:
// each noise component keeps its detail while its lattice period spans at
// least 4 of the level's voxels and fades to its mean by 2 (the level's
// Nyquist limit), so a coarse level shows what a mean of the finer one
// would (a speckle field becomes its average share) without aliasing. A
// true mean pyramid is not computed: level l of 8192^3 would need 8^l
// evaluations per voxel (2^39 for the 16^3 top), so meanPyramid() stays
// false and bricks are read before the TF may skip them.
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
  // The fields as a level whose voxel spans `voxel` level-0 voxels sees
  // them (band-limited, see above); voxel 1 is the field itself.
  double fieldAt(glm::dvec3 x, double voxel) const;
  double field16At(glm::dvec3 x, double voxel) const;
  // The stored value of level `level`'s voxel `voxel`, computed directly
  // (what readBox returns at that voxel; the tests' direct indexing).
  double levelValue(int level, glm::ivec3 voxel) const;

 private:
  std::string spec_;
  Volume shape_;
  std::vector<glm::ivec3> dims_;
  bool sixteen_ = false;
};

}  // namespace tessera::lod
