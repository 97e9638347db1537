#pragma once
// One whole level of a pyramid in host memory, placed where the bricks
// layout shows it: what the CPU reference of a streamed volume reads
// (session/RenderRun.h).
#include <cstdint>
#include <string>

#include "tessera/core/Volume.h"
#include "tessera/lod/MultiresSource.h"

namespace tessera::lod {

// The bytes readLevel(source, level) allocates for the voxels.
std::uint64_t levelBytes(const MultiresSource& source, int level);

// "level 1 (75x70x65 u16, 677 KiB)": how errors and reports name a level.
std::string describeLevel(const MultiresSource& source, int level);

// Level `level` read whole (readBox over its dims), after its bytes are
// checked against the host budget (BudgetError naming the level, its size
// and the budget). Its geometry is where lod::BrickGrid and bricks.glsl put
// it, whatever the store's metadata says: with s = lod::levelScale(source,
// level) per axis (2^l in a factor-2 pyramid, (1, 2^l, 2^l) where z is
// kept), level-l voxel i covers level-0 voxels [i s, (i + 1) s), so its
// centre lies at level-0 index (i + 0.5) s - 0.5: spacing s times level 0's,
// level 0's direction, the origin (s - 1) / 2 level-0 voxels in
// (lod::downsample's placement). The level's box reaches past level 0's by
// up to s - 1 level-0 voxels where s does not divide the dims; the bricks
// layout clamps to level 0's box (reference::PyramidLevelReconstruction does
// the same). InputError for a level outside 0..levelCount() - 1, or a
// pyramid whose levels do not reduce by integer factors.
Volume readLevel(const MultiresSource& source, int level);

}  // namespace tessera::lod
