#pragma once
// The platform's roofline for volume rendering: how many trilinear 3D
// texture fetches and transfer-function lookups per second the current
// context can take at all, measured with full-screen passes of N fetches per
// fragment (summed into a float target, so none can be optimised away) and
// timed to glFinish. A technique's effective samples per second divided by
// these peaks says how much of the platform it uses, and so whether the lever
// left is cheaper samples or fewer of them.
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/gpu/GlContext.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/LookupTexture.h"
#include "tessera/gpu/Program.h"

namespace tessera::render {

enum class RooflineKernel {
  // N trilinear fetches along a ray-like walk whose addresses are known up
  // front (what a ray caster's loop is, ERT aside).
  Fetch3DIndependent,
  // The same walk, each address depending on the previous fetch's value: the
  // latency-bound case.
  Fetch3DDependent,
  // N linear lookups of a 4096-entry RGBA lookup texture (the baked TF's
  // format) at scattered positions.
  TfLookup,
  // N trilinear fetches each followed by the TF lookup of its value: the
  // post-classified sample every ray caster takes.
  Fetch3DThenTf,
  // The same with the table unfiltered (nearest entry of 4096).
  Fetch3DThenTfNearest,
  // The same with the TF evaluated in the shader instead of looked up (the
  // `bench` preset's two-segment opacity ramp and grey ramp): what a
  // piecewise-linear TF of a few points would cost.
  Fetch3DThenTfInShader,
};

const char* rooflineKernelName(RooflineKernel kernel);

struct RooflineOptions {
  glm::ivec3 volumeDims{256};  // the 3D texture (R8, random voxels)
  int width = 512;             // the pass's target
  int height = 512;
  int fetchesPerFragment = 128;
  int repeats = 5;  // timed passes per kernel (after one untimed)
};

struct RooflineRate {
  RooflineKernel kernel;
  double msMedian = 0.0;          // a pass of N fetches per fragment
  double msEmptyMedian = 0.0;     // the same pass with no fetches: the fixed cost
  double fetchesPerSecond = 0.0;  // width * height * N / (ms - msEmpty)
};

// The kernels' programs and inputs, built once; each measurePass() times one
// pass of every kernel and of its no-fetch twin, so a benchmark can
// interleave them with the frames it compares them with. Needs an ES 3
// context (3D textures): GpuError otherwise.
class RooflineProbe {
 public:
  RooflineProbe(gpu::GlContext& context, const RooflineOptions& options);
  void measurePass();
  // Medians over the passes so far (at least one).
  std::vector<RooflineRate> rates() const;

 private:
  struct KernelRun {
    RooflineKernel kernel;
    gpu::Program full;
    gpu::Program empty;
    std::vector<double> ms;
    std::vector<double> emptyMs;
  };
  void bindInputs(const gpu::Program& program) const;
  double timedPass() const;  // the bound program, to glFinish

  RooflineOptions options_;
  gpu::Texture volume_;
  gpu::LookupTexture lut_;
  gpu::Texture nearestLut_;  // the same table, unfiltered
  gpu::FullscreenTriangle triangle_;
  gpu::Framebuffer target_;
  std::vector<KernelRun> runs_;
};

// options.repeats passes of a fresh probe.
std::vector<RooflineRate> measureRoofline(gpu::GlContext& context, const RooflineOptions& options);

}  // namespace tessera::render
