#pragma once
// `tessera bench --sampling` (fewer samples for the same
// image). The ablation: the ray caster as it was (post-classification, every
// sample), + pre-integration, + adaptive steps, and both, at each base step,
// frames interleaved; per variant the median frame time, the samples per ray
// it took (counted by the CPU reference walking the same samples) and the
// PSNR against a fine reference (0.25 voxel, every sample, post-classified).
// `--sampling-sweep` runs candidate settings over several volumes, TFs and
// shading to choose `tessera render`'s defaults (docs/sampling.md).
#include <string>
#include <vector>

#include "cli/ShadingOptions.h"

namespace tessera::app {

struct SamplingBenchOptions {
  std::vector<std::string> volumes;  // empty: ch2 (or the phantom)
  std::vector<std::string> tfs{"bench"};
  std::vector<double> steps{0.5, 1.0};
  std::string size = "512x512";
  int frames = 8;  // per variant, rotating `rotate` degrees, interleaved
  double rotate = 10.0;
  double referenceStep = 0.25;
  int views = 2;  // quality: the worst PSNR over this many views (azimuth 0, 60, ...)
  std::vector<std::string> shading{"off"};  // "off", "on" or both
  ShadingOptions shadingOptions;
  double tolerance = 0.1;                          // adaptive variants of the ablation
  std::vector<double> tolerances{0.25, 0.5, 1.0};  // the sweep's
  int maxMultiplier = 16;
  int preintEntries = 256;
  bool sweep = false;  // candidate settings instead of the ablation
  bool json = false;
};

void runSamplingBench(const SamplingBenchOptions& options);

}  // namespace tessera::app
