#pragma once
// `tessera bench --scale`: the generated u16 head (head16:N, computed brick
// by brick, never held) from 512^3 to 8192^3 (1 TiB) through the bricks
// layout on device profiles: time to the first and to the refined image,
// the bricks generated (and their bytes), the texture peak from the ledger
// against the profile's budget, and the process's peak RSS against the host
// budget. Each (size, profile) runs in its own child process, so every RSS
// peak is that row's alone. docs/large-data.md "Scale" holds the table.
#include <string>
#include <vector>

namespace tessera::app {

struct ScaleBenchOptions {
  std::vector<int> sides{512, 1024, 2048, 4096, 8192};
  std::vector<std::string> profiles{"webgl2", "ipad2"};
  std::string size = "512x512";
  std::string tf = "ct-bone";
};

// The ray caster's settings for an N^3 volume at an image of `pixels` on
// its longer side: a step of half a voxel of the level a pixel resolves
// (N / pixels level-0 voxels, capped at the settings' 8), and an
// empty-space block of max(8, N / 128) voxels so the block grid stays at
// most 128^3 (8 MiB) whatever N.
double scaleStepVoxels(int side, int pixels);
int scaleSkipBlock(int side);

void runScaleBench(const ScaleBenchOptions& options);

}  // namespace tessera::app
