#pragma once
// `tessera bench --bricks`: large generated volumes (head:WxHxD, computed
// brick by brick) streamed through the bricks layout on device profiles:
// time to the first and to the refined image, frame time while rotating
// (streaming as it goes), texture bytes against the budget, levels used,
// bricks read, the process's peak RSS (always --layout bricks); and, where
// the volume also fits the profile in core, the in-core layout's rotating frame time in the same
// run as the baseline of the ratio.
#include <cstdint>
#include <string>
#include <vector>

namespace tessera::app {

struct BricksBenchOptions {
  std::vector<std::string> volumes{"head:512x512x894", "head:1024"};
  std::vector<std::string> profiles{"shield-k1", "ipad2"};
  std::string size = "512x512";
  int frames = 8;  // rotating frames after the refined first one
  double rotate = 10.0;
  std::string tf = "ct-bone";
  bool baseline = true;  // also render in core where the profile holds it
};

void runBricksBench(const BricksBenchOptions& options);

// Shared with `bench --scale`: this process's peak resident set, and the
// bricks wanted per level as "L0:12 L1:3" (levels with none left out).
std::uint64_t peakRssBytes();
std::string levelsText(const std::vector<int>& perLevel);

}  // namespace tessera::app
