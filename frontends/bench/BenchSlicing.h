#pragma once
// `tessera bench --slicing`: the texture-slicing benchmarks —
// GRAPP 2012 Tables 1-2 (ms/frame and fps of ray casting by steps and
// view-aligned slicing by slices, plus axis-aligned slicing), the
// TF-update times in the shape of Moser & Weiskopf 2008 Figure 6, and the
// quality of each technique at each count against the CPU reference.
#include <string>

namespace tessera::app {

struct SlicingBenchOptions {
  std::string file;  // volume spec; default ch2
  int frames = 3;    // per cell, rotating; the median is reported
  std::string tf = "bench";
  std::string outDir;  // when set: bench-slicing.md and the SVG plots there
  bool quick = false;  // one resolution and two counts (a smoke run)
};

void runSlicingBench(const SlicingBenchOptions& options);

}  // namespace tessera::app
