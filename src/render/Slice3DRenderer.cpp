#include "tessera/render/Slice3DRenderer.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "render/SampleParts.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/Draw.h"
#include "tessera/render/ClippingUniforms.h"
#include "tessera/render/ShadingUniforms.h"
#include "tessera/render/SliceProjection.h"

namespace tessera::render {

Slice3DRenderer::Slice3DRenderer(gpu::GlContext& context, const Volume& volume,
                                 const layout::Layout& layout,
                                 std::optional<bool> halfFloatAccumulation)
    : context_(context),
      volume_(volume),
      layout_(layout),
      tf_(TransferFunction::preset("grey")),
      accumulator_(context, halfFloatAccumulation),
      gradient_(context, volume, layout, kOwnTextureUnits) {}

void Slice3DRenderer::setTransferFunction(const TransferFunction& tf) {
  tf_ = tf;
  lookupKey_.clear();
}

void Slice3DRenderer::setSlabSamples(int samples) {
  if (samples < 0 || samples > kMaxSlabSamples) {
    throw InputError("samples a slab must be 1.." + std::to_string(kMaxSlabSamples) +
                     " (0 = from the accumulation target), got " + std::to_string(samples));
  }
  requestedSlabSamples_ = samples;
}

int Slice3DRenderer::slabSamplesFor(const RenderSettings& settings) const {
  // MIP's maxima are exact in any target; a half-float target keeps every
  // plane's small contribution.
  if (settings.mode == RenderMode::Mip) return 1;
  if (requestedSlabSamples_ > 0) return requestedSlabSamples_;
  return accumulator_.roundsTo8Bits() ? kRgba8SlabSamples : 1;
}

bool Slice3DRenderer::ditherFor(const RenderSettings& settings) const {
  return settings.mode != RenderMode::Mip && accumulator_.roundsTo8Bits();
}

void Slice3DRenderer::setSliceCount(int slices) {
  if (slices < 0 || slices > kMaxSlices) {
    throw InputError("slice count must be 1.." + std::to_string(kMaxSlices) +
                     " (0 = from the step), got " + std::to_string(slices));
  }
  requestedSlices_ = slices;
}

int Slice3DRenderer::sliceCountFor(const RenderSettings& settings) const {
  if (requestedSlices_ > 0) return requestedSlices_;
  const double ds = sampleDistance(settings, volume_.spacing());
  const double n = std::ceil(glm::length(volume_.extent()) / ds - 1e-9);
  if (n > kMaxSlices) {
    throw InputError("a step of " + std::to_string(settings.stepVoxels) + " voxels needs " +
                     std::to_string(static_cast<long long>(n)) + " slices, more than " +
                     std::to_string(kMaxSlices) + "; use a larger --step or --slices");
  }
  return std::max(1, static_cast<int>(n));
}

double Slice3DRenderer::sliceSpacingFor(const RenderSettings& settings) const {
  return glm::length(volume_.extent()) / sliceCountFor(settings);
}

std::uint64_t Slice3DRenderer::ownTextureBytes() const {
  return lut_.texture().bytes() + accumulator_.ownTextureBytes() + vertices_.bytes() +
         gradient_.bytes();
}

void Slice3DRenderer::buildGeometry(int slices, int slabSamples) {
  // Two triangles per slab in cube units: x, y in [-0.5, 0.5], the planes
  // at z = 0.5 - (k + 0.5) / N, a slab's quad on its first plane
  // (k = m * slabSamples), so the buffer's order is front to back. The last
  // slab's planes past the cube's back lie outside the volume.
  const int slabs = (slices + slabSamples - 1) / slabSamples;
  std::vector<float> v;
  v.reserve(static_cast<std::size_t>(slabs) * 18);
  constexpr float corners[6][2] = {{-0.5f, -0.5f}, {0.5f, -0.5f}, {0.5f, 0.5f},
                                   {-0.5f, -0.5f}, {0.5f, 0.5f},  {-0.5f, 0.5f}};
  for (int m = 0; m < slabs; ++m) {
    const double k = static_cast<double>(m) * slabSamples;
    const float z = static_cast<float>(0.5 - (k + 0.5) / slices);
    for (const auto& c : corners) {
      v.push_back(c[0]);
      v.push_back(c[1]);
      v.push_back(z);
    }
  }
  vertices_ = gpu::Buffer();
  vertices_ =
      gpu::Buffer::create(context_.ledger(), "slice3d proxy cube", gpu::BufferKind::Vertices,
                          v.size() * sizeof(float), v.data(), gpu::BufferUsage::Static);
  builtSlices_ = slices;
  builtSlabSamples_ = slabSamples;
  builtSlabs_ = slabs;
  ++geometryBuilds_;
}

void Slice3DRenderer::updateLookup(const RenderSettings& settings, double spacing) {
  const ValueRange w = volume_.window();
  std::ostringstream key;
  key.precision(17);
  key << spacing << '|' << settings.opacityScale << '|' << w.min << '|' << w.max << '|'
      << settings.nearest << '|' << tf_.toJson();
  if (key.str() == lookupKey_) return;
  lookupKey_ = key.str();
  // Nearest (labels): 256 entries, one per 8-bit value, so that a label's
  // entry is never mixed with its neighbour's.
  lut_.upload(context_, tf_.bake(settings.nearest ? 256 : 4096, spacing, settings.opacityScale),
              "slice3d transfer function");
}

std::vector<gpu::ShaderPart> Slice3DRenderer::vertexParts() const {
  return {gpu::shaderPreamble(context_.caps().api, false, {}),
          gpu::embeddedShaderPart("render/slice3d.vert.glsl")};
}

std::vector<gpu::ShaderPart> Slice3DRenderer::fragmentParts(const RenderSettings& settings) const {
  std::vector<std::string> defines;
  if (settings.mode == RenderMode::Mip) defines.push_back("MODE_MIP 1");
  addShadingDefines(settings, defines);
  gradient_.addDefines(settings, defines);
  addClippingDefines(settings, defines);
  if (settings.nearest) defines.push_back("NEAREST 1");
  defines.push_back("SLAB_SAMPLES " + std::to_string(slabSamplesFor(settings)));
  if (ditherFor(settings)) defines.push_back("DITHER_8BIT 1");
  std::vector<gpu::ShaderPart> parts = {gpu::shaderPreamble(context_.caps().api, true, defines)};
  addSampleParts(parts, gradient_, layout_);
  parts.push_back(gpu::embeddedShaderPart("render/slice_opacity.glsl"));
  parts.push_back(gpu::embeddedShaderPart("render/slice3d.frag.glsl"));
  return parts;
}

const gpu::Program& Slice3DRenderer::programFor(const RenderSettings& settings) {
  const std::string key =
      layout_.name() + (settings.mode == RenderMode::Mip ? "|mip" : "") +
      (shadingActive(settings) ? "|shade" : "") +
      (gradient_.precomputed(settings) ? "|gradient-texture" : "") +
      (gradient_.valuesFromGradient(settings) ? "|values" : "") +
      (settings.clipping.active() ? "|clip" : "") + (settings.nearest ? "|nearest" : "") +
      "|slab " + std::to_string(slabSamplesFor(settings)) + (ditherFor(settings) ? "|dither" : "");
  return programs_.get(key, [&] {
    return gpu::Program::build("slice3d(" + key + ")", vertexParts(), fragmentParts(settings));
  });
}

void Slice3DRenderer::prepare(const RenderSettings& settings) {
  if (settings.mode == RenderMode::MinIp || settings.mode == RenderMode::Average) {
    throw InputError(
        "slice3d blends composite and MIP only; MinIP and the average need the ray "
        "caster (--technique raycast)");
  }
  const int n = sliceCountFor(settings);
  const int k = slabSamplesFor(settings);
  if (n != builtSlices_ || k != builtSlabSamples_) buildGeometry(n, k);
  updateLookup(settings, settings.mode == RenderMode::Mip ? tf_.opacityUnitLength
                                                          : sliceSpacingFor(settings));
  gradient_.prepare(settings);
  programFor(settings);
}

void Slice3DRenderer::renderFrame(const Camera& camera, const RenderSettings& settings, int width,
                                  int height) {
  prepare(settings);
  accumulator_.begin(width, height, settings.mode);

  // Cube -> world: scale by the diagonal and turn by the camera basis
  // (columns right, up, back), so cube +z points at the viewer. The volume
  // box is centred at the world origin, and so is the cube.
  const double d = glm::length(volume_.extent());
  const glm::dmat3 b = camera.basis();
  glm::dmat4 cubeToWorld(1.0);
  for (int c = 0; c < 3; ++c) cubeToWorld[c] = glm::dvec4(b[c] * d, 0.0);
  // World -> texture: the unit box of sampleVolume().
  const glm::dvec3 extent = volume_.extent();
  glm::dmat4 worldToTexture = glm::translate(glm::dmat4(1.0), glm::dvec3(0.5));
  worldToTexture = glm::scale(worldToTexture, 1.0 / extent);
  const glm::dmat4 worldToView = sliceWorldToView(camera);
  const double aspect = static_cast<double>(width) / height;
  const glm::dmat4 projection = sliceViewToClip(camera, aspect, glm::length(camera.eye()) + d);
  const glm::dmat4 cubeToView = worldToView * cubeToWorld;

  const gpu::Program& prog = programFor(settings);
  prog.use();
  prog.set("u_cubeToClip", glm::mat4(projection * cubeToView));
  const glm::dmat4 cubeToTexture = worldToTexture * cubeToWorld;
  prog.set("u_cubeToTexture", glm::mat4(cubeToTexture));
  prog.set("u_cubeToView", glm::mat4(cubeToView));
  prog.set("u_ortho", camera.projection == Projection::Orthographic ? 1.0f : 0.0f);
  // A slab's planes behind its first (slice3d.frag.glsl): one plane's step
  // along the cube's -z (orthographic), or the eye's texture position and
  // the planes' spacing (perspective).
  prog.set("u_planeStep",
           glm::vec3(cubeToTexture * glm::dvec4(0.0, 0.0, -1.0 / builtSlices_, 0.0)));
  prog.set("u_eyeTexture", glm::vec3(worldToTexture * glm::dvec4(camera.eye(), 1.0)));
  prog.set("u_slabsPerCube", static_cast<float>(builtSlices_) / builtSlabSamples_);
  prog.set("u_planeSpacing", static_cast<float>(d / builtSlices_));
  const layout::ValueMapping m = layout_.rawFromStored();
  const ValueRange w = volume_.window();
  const double ww = w.max - w.min;
  prog.set("u_valueScale", static_cast<float>(m.scale / ww));
  prog.set("u_valueBias", static_cast<float>((m.offset - w.min) / ww));
  setShadingUniforms(prog, settings, camera, m.scale / ww, extent, volume_.spacing());
  setClippingUniforms(prog, settings, camera, extent);
  if (settings.nearest) prog.set("u_sampleDims", glm::vec3(volume_.dims()));
  int unit = layout_.bindSeam(prog, 0);
  unit += gradient_.bind(prog, unit, settings);
  lut_.texture().bind(unit);
  prog.set("u_tf", unit);
  prog.set("u_tfSize", static_cast<float>(lut_.entries()));

  if (settings.mode == RenderMode::Mip && layout_.drawsChannels()) {
    drawChannelMaxima(prog, settings);
    return;
  }
  gpu::drawArrays(gpu::Primitive::Triangles, vertices_, {{0, 3, 0}}, 3, 0, builtSlabs_ * 6);
  accumulator_.resolve(settings, &lut_.texture(), lut_.entries());
}

// Several channels' maxima (docs/channels.md): the slices twice, channels
// 0-3 into the accumulation target and 4-5 with the hit flag into a second
// (one RGBA target a pass: ES 2 has no multiple render targets), then the
// resolve that colours them.
void Slice3DRenderer::drawChannelMaxima(const gpu::Program& slices,
                                        const RenderSettings& settings) {
  for (int group = 0; group < 2; ++group) {
    if (group == 1) accumulator_.beginSecond(settings.mode);
    slices.set("u_channelGroup", static_cast<float>(group));
    gpu::drawArrays(gpu::Primitive::Triangles, vertices_, {{0, 3, 0}}, 3, 0, builtSlabs_ * 6);
  }
  const gpu::Program& resolve = channelResolveProgram();
  resolve.use();
  const int unit = layout_.bindSeam(resolve, 0);
  accumulator_.resolveWith(resolve, unit, settings);
}

std::vector<gpu::ShaderPart> Slice3DRenderer::channelResolveParts() const {
  std::vector<gpu::ShaderPart> frag = {gpu::shaderPreamble(context_.caps().api, true, {})};
  addSampleParts(frag, gradient_, layout_);
  frag.push_back(gpu::embeddedShaderPart("render/slice_channels_resolve.frag.glsl"));
  return frag;
}

const gpu::Program& Slice3DRenderer::channelResolveProgram() {
  return programs_.get(layout_.name() + "|channel maxima resolve", [&] {
    const gpu::ApiLevel api = context_.caps().api;
    return gpu::Program::build("slice3d channel maxima resolve",
                               {gpu::shaderPreamble(api, false, {}),
                                gpu::embeddedShaderPart("render/fullscreen.vert.glsl")},
                               channelResolveParts());
  });
}

// ---- The Technique interface and the registry's entry.

void Slice3DRenderer::prepare(const Camera&, const RenderSettings& settings) {
  prepare(settings);
}

const gpu::Texture& Slice3DRenderer::render(const Camera& camera, const RenderSettings& settings,
                                            int width, int height, double viewAspect) {
  const glm::ivec2 size = sliceTargetSize(width, height, viewAspect);
  renderFrame(camera, settings, size.x, size.y);
  return colorTexture();
}

TechniqueReport Slice3DRenderer::report() const {
  TechniqueReport r;
  r.note = "slice3d: " + std::to_string(builtSlices_) + " view-aligned slices";
  if (builtSlabSamples_ > 1) {
    r.note += " in " + std::to_string(builtSlabs_) + " slabs of " +
              std::to_string(builtSlabSamples_) + " samples";
  }
  r.note += ", accumulation " + accumulationFormat() + ", no early termination";
  r.gradient = gradient_.plan().reason;
  return r;
}

TechniqueRequirements Slice3DRenderer::requirements(const gpu::DeviceLimits&, glm::ivec3,
                                                    const TechniqueOptions& options) {
  TechniqueRequirements r;
  r.textureUnits = kOwnTextureUnits;
  // The frame's target and the TF table, reserved as for the ray caster
  // without its grid, and the proxy geometry.
  r.bytes = static_cast<std::uint64_t>(options.imageSize.x) *
                static_cast<std::uint64_t>(options.imageSize.y) * 4 +
            4096 * 8 + 4096;
  return r;
}

std::unique_ptr<Slice3DRenderer> Slice3DRenderer::create(const TechniqueSetup& s) {
  if (!s.layout) throw Error("slice3d samples a layout, and none was made");
  auto slicer = std::make_unique<Slice3DRenderer>(s.context, s.volume, *s.layout,
                                                  s.limits.halfFloatRenderTargets);
  slicer->setSliceCount(s.options.slices);
  slicer->setGradient(layout::parseGradientWish(s.options.gradient));
  return slicer;
}

TechniqueEntry Slice3DRenderer::registration() {
  return {
      .name = "slice3d",
      .summary = "view-aligned slicing",
      .drawsChannels = true,
      .drawsChannelBricks = true,
      .requirements = &Slice3DRenderer::requirements,
      .create = [](const TechniqueSetup& s) -> std::unique_ptr<Technique> { return create(s); }};
}

}  // namespace tessera::render
