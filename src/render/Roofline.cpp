#include "tessera/render/Roofline.h"

#include <chrono>
#include <cstdint>
#include <random>

#include <glm/geometric.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/Timing.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/Draw.h"
#include "tessera/gpu/LookupTexture.h"
#include "tessera/gpu/Program.h"

namespace tessera::render {

namespace {

constexpr RooflineKernel kKernels[] = {RooflineKernel::Fetch3DIndependent,
                                       RooflineKernel::Fetch3DDependent,
                                       RooflineKernel::TfLookup,
                                       RooflineKernel::Fetch3DThenTf,
                                       RooflineKernel::Fetch3DThenTfNearest,
                                       RooflineKernel::Fetch3DThenTfInShader};

gpu::Program kernelProgram(const gpu::GlContext& context, RooflineKernel kernel, int fetches) {
  const gpu::ApiLevel api = context.caps().api;
  const std::vector<std::string> defines = {
      "ROOFLINE_FETCHES " + std::to_string(fetches),
      "ROOFLINE_KERNEL " + std::to_string(static_cast<int>(kernel))};
  return gpu::Program::build(
      std::string("roofline(") + rooflineKernelName(kernel) + ")",
      {gpu::shaderPreamble(api, false, {}), gpu::embeddedShaderPart("render/fullscreen.vert.glsl")},
      {gpu::shaderPreamble(api, true, defines),
       gpu::embeddedShaderPart("render/roofline.frag.glsl")});
}

// Random voxels: no two neighbouring fetches are the same value, so the TF
// lookups of the combined kernel scatter as they do on real data.
gpu::Texture randomVolume(gpu::GlContext& context, glm::ivec3 dims) {
  std::vector<std::uint8_t> voxels(static_cast<std::size_t>(dims.x) * dims.y * dims.z);
  std::mt19937 rng(16);
  for (std::uint8_t& v : voxels) v = static_cast<std::uint8_t>(rng() >> 24);
  gpu::Texture t = gpu::Texture::create3D(context.ledger(), "roofline volume", gpu::TexelFormat::R8,
                                          dims.x, dims.y, dims.z, voxels.data());
  t.setFilter(gpu::Filter::Linear);
  return t;
}

constexpr int kLutEntries = 4096;

std::vector<float> rampTable() {
  std::vector<float> rgba(4 * kLutEntries);
  for (int i = 0; i < kLutEntries; ++i) {
    const float x = static_cast<float>(i) / (kLutEntries - 1);
    rgba[4 * i + 0] = rgba[4 * i + 1] = rgba[4 * i + 2] = x;
    rgba[4 * i + 3] = 0.01f * x;
  }
  return rgba;
}

gpu::LookupTexture rampLookup(gpu::GlContext& context) {
  gpu::LookupTexture lut;
  lut.upload(context, rampTable(), "roofline transfer function", gpu::Filter::Linear);
  return lut;
}

gpu::Texture nearestRampLookup(gpu::GlContext& context) {
  const std::vector<float> rgba = rampTable();
  gpu::Texture t = gpu::Texture::create2D(context.ledger(), "roofline nearest transfer function",
                                          gpu::TexelFormat::RGBA16F, kLutEntries, 1, rgba.data());
  t.setFilter(gpu::Filter::Nearest);
  return t;
}

}  // namespace

const char* rooflineKernelName(RooflineKernel kernel) {
  switch (kernel) {
    case RooflineKernel::Fetch3DIndependent:
      return "trilinear 3D fetch, independent";
    case RooflineKernel::Fetch3DDependent:
      return "trilinear 3D fetch, dependent";
    case RooflineKernel::TfLookup:
      return "TF lookup (4096-entry table, linear)";
    case RooflineKernel::Fetch3DThenTf:
      return "3D fetch + TF lookup (a classified sample)";
    case RooflineKernel::Fetch3DThenTfNearest:
      return "3D fetch + TF lookup, nearest";
    case RooflineKernel::Fetch3DThenTfInShader:
      return "3D fetch + TF evaluated in the shader";
  }
  return "?";
}

RooflineProbe::RooflineProbe(gpu::GlContext& context, const RooflineOptions& o) : options_(o) {
  if (context.caps().api != gpu::ApiLevel::Gles3 || context.caps().max3DTextureSize == 0) {
    throw GpuError("the roofline needs an ES 3 context with 3D textures");
  }
  if (o.fetchesPerFragment < 1 || o.repeats < 1) {
    throw InputError("roofline: fetches per fragment and repeats must be >= 1");
  }
  volume_ = randomVolume(context, o.volumeDims);
  lut_ = rampLookup(context);
  nearestLut_ = nearestRampLookup(context);
  triangle_ = gpu::FullscreenTriangle(context.ledger());
  const bool floatTarget = gpu::DeviceLimits::of(context.caps()).floatRenderTargets;
  target_ = gpu::Framebuffer::create(
      context.ledger(), "roofline target", o.width, o.height,
      floatTarget ? gpu::TexelFormat::RGBA16F : gpu::rgba8For(context.caps().api));
  target_.bind();
  gpu::apply({});
  for (RooflineKernel kernel : kKernels) {
    KernelRun run{kernel,
                  kernelProgram(context, kernel, o.fetchesPerFragment),
                  kernelProgram(context, kernel, 0),
                  {},
                  {}};
    for (const gpu::Program* p : {&run.full, &run.empty}) {
      bindInputs(*p);
      timedPass();  // untimed: the driver's first draw compiles variants
    }
    runs_.push_back(std::move(run));
  }
}

void RooflineProbe::bindInputs(const gpu::Program& program) const {
  program.use();
  volume_.bind(0);
  program.set("u_volume", 0);
  lut_.texture().bind(1);
  nearestLut_.bind(2);
  program.set("u_tf", 1);
  program.set("u_tfNearest", 2);
  program.set("u_viewport", glm::vec2(options_.width, options_.height));
  // Half a voxel per step along a diagonal that is mostly depth, like the
  // rays of a front view.
  const glm::vec3 direction = glm::normalize(glm::vec3(0.3f, 0.2f, 1.0f));
  program.set("u_delta", 0.5f * direction / glm::vec3(options_.volumeDims));
}

double RooflineProbe::timedPass() const {
  const auto t0 = std::chrono::steady_clock::now();
  triangle_.draw();
  gpu::finish();
  return msSince(t0);
}

void RooflineProbe::measurePass() {
  // Other passes may have run since the last one: bind everything again.
  target_.bind();
  gpu::apply({});
  for (KernelRun& run : runs_) {
    bindInputs(run.full);
    run.ms.push_back(timedPass());
    bindInputs(run.empty);
    run.emptyMs.push_back(timedPass());
  }
  gpu::checkErrors("roofline");
}

std::vector<RooflineRate> RooflineProbe::rates() const {
  std::vector<RooflineRate> rates;
  const double fetches =
      static_cast<double>(options_.width) * options_.height * options_.fetchesPerFragment;
  for (const KernelRun& run : runs_) {
    if (run.ms.empty()) throw InputError("roofline: no pass measured yet");
    RooflineRate rate{run.kernel, median(run.ms), median(run.emptyMs), 0.0};
    const double busyMs = rate.msMedian - rate.msEmptyMedian;
    rate.fetchesPerSecond = busyMs > 0.0 ? fetches / (busyMs * 1e-3) : 0.0;
    rates.push_back(rate);
  }
  return rates;
}

std::vector<RooflineRate> measureRoofline(gpu::GlContext& context, const RooflineOptions& o) {
  RooflineProbe probe(context, o);
  for (int r = 0; r < o.repeats; ++r) probe.measurePass();
  return probe.rates();
}

}  // namespace tessera::render
