#pragma once
// `tessera bench --roofline`: the context's peak trilinear
// 3D fetch and TF lookup rates (render/Roofline.h), then each technique's
// effective samples per second on a real volume as a fraction of them.
#include <string>

namespace tessera::app {

struct RooflineBenchOptions {
  std::string file;  // volume spec; default ch2
  std::string size = "512x512";
  int frames =
      5;  // per technique and peak kernel, at one view (every frame takes the same samples)
  double step = 0.5;
  std::string tf = "bench";
  int fetches = 128;  // per fragment in the peak passes
  bool json = false;
};

void runRooflineBench(const RooflineBenchOptions& options);

}  // namespace tessera::app
