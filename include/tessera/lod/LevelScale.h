#pragma once
// How each level of a pyramid reduces the one before it, per axis. Level
// l + 1 reduces level l by an integer factor along each axis, its dims
// ceil or floor of dims_l / factor: 2 halves the axis (tessera convert,
// lod::downsample), 1 keeps it (microscopy's (1, 2, 2) scales keep z while
// x and y are halved). A level-l voxel i then covers level-0 voxels
// [i s, (i + 1) s) along an axis, s = levelScale(l) (the product of the
// factors up to l): where lod::BrickGrid, bricks.glsl, lod::readLevel and
// reference::PyramidLevelReconstruction put it.
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/lod/MultiresSource.h"

namespace tessera::lod {

// The factor of every level (level 0's is 1), from the level dims; the
// level spacing decides where the dims allow several (an axis of one voxel:
// 1 -> 1 is kept or halved alike). InputError naming `what`, the level and
// the axis when no integer factor gives a level's dims.
std::vector<glm::ivec3> levelFactors(const std::vector<LevelInfo>& levels, const std::string& what);
std::vector<glm::ivec3> levelFactors(const MultiresSource& source);

// Level-0 voxels per level-l voxel along each axis: the product of the
// factors of levels 1..l (1 at level 0).
std::vector<glm::ivec3> levelScales(const std::vector<glm::ivec3>& factors);
glm::ivec3 levelScale(const MultiresSource& source, int level);

}  // namespace tessera::lod
