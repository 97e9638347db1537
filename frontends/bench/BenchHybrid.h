#pragma once
// `tessera bench --hybrid` and `tessera bench --interactive`: the hybrid
// low/high-resolution compositor's quality (each line-attenuation method vs
// the ground truth, as numbers for Moser & Weiskopf's Figure 2) and speed
// (full resolution vs offscreen sizes), and the quality controller holding a
// frame-time goal during a simulated interaction.
#include <string>

namespace tessera::app {

struct HybridBenchOptions {
  std::string file;     // volume (default: ch2)
  int frames = 8;       // timed frames per variant (speed), moving frames (interactive)
  double rotate = 5.0;  // azimuth step per frame
  double step = 0.5;    // sample distance in voxels
  std::string tf = "bench";
  std::string outDir;   // --hybrid: where the pictures go (none when empty)
  double goalMs = 0.0;  // --interactive: frame-time goal (0: a tenth of a full frame)
  std::string size = "480x640";
  bool json = false;
};

void runHybridBench(const HybridBenchOptions& options);       // BenchHybrid.cpp
void runInteractiveBench(const HybridBenchOptions& options);  // BenchInteractive.cpp

}  // namespace tessera::app
