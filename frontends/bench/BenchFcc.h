#pragma once
// `tessera bench --fcc`: Sarfaraz & Shaban 2015, Tables 1-2 in shape — 64^3-class
// volumes (Marschner-Lobb, Shepp-Logan, ch2 reduced) rendered by the same ray
// caster from the Cartesian grid (trilinear) and from their FCC lattices at
// the same and at half the sample count (box spline), at one image size,
// frames interleaved in one process; then where the box spline's time goes.
#include <string>

namespace tessera::app {

struct FccBenchOptions {
  std::string size = "512x512";
  int frames = 12;  // per variant, rotating; the median is reported
  double rotate = 10.0;
  double step = 0.5;
  std::string tf = "bench";
  bool json = false;
};

void runFccBench(const FccBenchOptions& options);

// `--fcc-out DIR`: the quality figures (BenchFccQuality.cpp) — Marschner-Lobb
// RMS and PSNR tables, ch2 on FCC vs the original — and their PNGs in DIR.
void runFccQuality(const std::string& outDir, int size);

}  // namespace tessera::app
