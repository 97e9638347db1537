#pragma once
// `tessera bench --bricks-vs-incore`: what the bricks layout costs against
// the in-core layout for volumes that fit both: the same view rendered
// through each, alternating runs, the refined bricked frame (every brick at
// level 0) against the in-core frame, and the PSNR between their images.
#include <string>
#include <vector>

namespace tessera::app {

struct BrickWalkBenchOptions {
  // Files or generator specs; "u16:SPEC" widens SPEC to 16 bits.
  std::vector<std::string> volumes;
  std::string size = "512x512";
  int frames = 6;  // per run; the first is not counted
  int rounds = 3;  // alternating bricked / in-core runs
  std::string tf = "mr-default";
};

void runBrickWalkBench(const BrickWalkBenchOptions& options);

}  // namespace tessera::app
