#include "tessera/render/Slice2DRenderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include <glm/geometric.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/Timing.h"
#include "tessera/gpu/Draw.h"
#include "tessera/render/ClippingUniforms.h"
#include "tessera/render/ShadingUniforms.h"
#include "tessera/render/SliceProjection.h"

namespace tessera::render {

namespace {

constexpr int kFloatsPerVertex = 7;  // position xyz, in-slice uv, tile origin xy

}  // namespace

const char* sliceClassificationName(SliceClassification c) {
  switch (c) {
    case SliceClassification::Pre:
      return "pre";
    case SliceClassification::Palette:
      return "palette";
    case SliceClassification::Post:
      return "post";
  }
  return "?";
}

SliceClassification parseSliceClassification(const std::string& name) {
  if (name == "pre") return SliceClassification::Pre;
  if (name == "palette") return SliceClassification::Palette;
  if (name == "post") return SliceClassification::Post;
  throw InputError("--classify '" + name + "': expected pre, palette or post");
}

Slice2DRenderer::Slice2DRenderer(gpu::GlContext& context, const Volume& volume,
                                 const Slice2DOptions& options)
    : context_(context),
      volume_(volume),
      options_(options),
      tf_(TransferFunction::preset("grey")),
      accumulator_(context, options.halfFloatAccumulation) {
  if (!options.channels) stacks_.emplace(volume);
  const int maxSize = options.maxTextureSize > 0
                          ? std::min(options.maxTextureSize, context.caps().max2DTextureSize)
                          : context.caps().max2DTextureSize;
  for (int axis = 0; axis < 3; ++axis) {
    plans_[axis] = planSliceAtlas(volume.dims(), axis, maxSize, options.powerOfTwoAtlases);
    buildGeometry(axis);
  }
}

Slice2DRenderer::~Slice2DRenderer() = default;

void Slice2DRenderer::setTransferFunction(const TransferFunction& tf) {
  tf_ = tf;
  classificationKey_.clear();
}

void Slice2DRenderer::setSliceCount(int slices) {
  if (slices < 0) throw InputError("slice count must be >= 1 (0 = every slice of the stack)");
  requestedSlices_ = slices;
}

void Slice2DRenderer::setSlabPlanes(int planes) {
  if (planes < 0 || planes > kMaxSlabPlanes) {
    throw InputError("planes a slab must be 1.." + std::to_string(kMaxSlabPlanes) +
                     " (0 = from the accumulation target), got " + std::to_string(planes));
  }
  requestedSlabPlanes_ = planes;
}

int Slice2DRenderer::slabPlanesFor(const RenderSettings& settings) const {
  // MIP's maxima are exact in any target; a half-float target keeps every
  // plane's small contribution; the single-volume stacks' planes are atlas
  // tiles (render/Slice2DRenderer.h).
  if (!options_.channels || settings.mode == RenderMode::Mip) return 1;
  if (requestedSlabPlanes_ > 0) return requestedSlabPlanes_;
  return accumulator_.roundsTo8Bits() ? kRgba8SlabPlanes : 1;
}

int Slice2DRenderer::stackAxisFor(const Camera& camera) {
  const glm::dvec3 f = glm::abs(camera.basis()[2]);
  // Ties go to the later axis, so that a view straight down a diagonal is stable.
  if (f.x > f.y && f.x > f.z) return 0;
  return f.y > f.z ? 1 : 2;
}

double Slice2DRenderer::baseDistance() const {
  const glm::dvec3 s = volume_.spacing();
  return std::min({s.x, s.y, s.z});
}

std::uint64_t Slice2DRenderer::stackTextureBytes() const {
  std::uint64_t bytes = 0;
  for (const auto& list : atlases_) {
    for (const auto& t : list) bytes += t.bytes();
  }
  return bytes;
}

std::uint64_t Slice2DRenderer::ownTextureBytes() const {
  std::uint64_t bytes =
      stackTextureBytes() + table_.texture().bytes() + accumulator_.ownTextureBytes();
  for (const auto& v : vertices_) bytes += v.bytes();
  for (const auto& [key, list] : drawLists_) bytes += list.indices.bytes() + list.vertices.bytes();
  return bytes;
}

void Slice2DRenderer::buildGeometry(int axis) {
  // One quad per voxel plane, slices in increasing order along the axis,
  // covering the whole world box face.
  const SliceAtlasPlan& p = plans_[axis];
  const glm::ivec2 a = sliceTileAxes(axis);
  const glm::dvec3 extent = volume_.extent();
  std::vector<float> v;
  v.reserve(static_cast<std::size_t>(p.slices) * 4 * kFloatsPerVertex);
  constexpr int corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int s = 0; s < p.slices; ++s) {
    const glm::ivec2 origin = p.tileOrigin(s);
    for (const auto& c : corners) {
      glm::dvec3 pos(0.0);
      pos[axis] = ((s + 0.5) / p.slices - 0.5) * extent[axis];
      pos[a.x] = (c[0] - 0.5) * extent[a.x];
      pos[a.y] = (c[1] - 0.5) * extent[a.y];
      v.insert(v.end(),
               {static_cast<float>(pos.x), static_cast<float>(pos.y), static_cast<float>(pos.z),
                static_cast<float>(c[0]), static_cast<float>(c[1]), static_cast<float>(origin.x),
                static_cast<float>(origin.y)});
    }
  }
  vertices_[axis] =
      gpu::Buffer::create(context_.ledger(), "slice2d stack geometry", gpu::BufferKind::Vertices,
                          v.size() * sizeof(float), v.data(), gpu::BufferUsage::Static);
}

const Slice2DRenderer::DrawList& Slice2DRenderer::drawList(int axis, bool descending, int slices) {
  const std::string key = std::to_string(axis) + (descending ? "-" : "+") + std::to_string(slices);
  auto it = drawLists_.find(key);
  if (it != drawLists_.end()) return it->second;
  const SliceAtlasPlan& p = plans_[axis];
  // Evenly spaced planes k = 0..N-1 at floor((k + 0.5) n / N); all when N = n.
  std::vector<int> chosen;
  for (int k = 0; k < slices; ++k) chosen.push_back(((2 * k + 1) * p.slices) / (2 * slices));
  if (descending) std::reverse(chosen.begin(), chosen.end());
  DrawList list;
  list.gapRatio = static_cast<double>(p.slices) / slices;
  std::vector<std::uint16_t> indices;
  for (int s : chosen) {
    const int atlas = p.atlasOf(s);
    if (list.ranges.empty() || list.ranges.back().atlas != atlas) {
      list.ranges.push_back({atlas, static_cast<int>(indices.size()), 0});
    }
    const auto base = static_cast<std::uint16_t>(s * 4);
    for (int i : {0, 1, 2, 0, 2, 3}) indices.push_back(static_cast<std::uint16_t>(base + i));
    list.ranges.back().count += 6;
  }
  list.indices = gpu::Buffer::create(
      context_.ledger(), "slice2d draw order", gpu::BufferKind::Indices16,
      indices.size() * sizeof(std::uint16_t), indices.data(), gpu::BufferUsage::Static);
  return drawLists_.emplace(key, std::move(list)).first->second;
}

// Channel frames: n planes across the axis at (k + 0.5) / n of the extent,
// front to back. One quad a slab of slabPlanes planes, on the slab's first
// (nearest) plane, widened by 2 (K - 1) plane spacings on each side (none
// for K = 1) so that its fragments reach the farther planes of oblique rays
// (render/Slice2DRenderer.h); its slab index in a_tile.z for the dither.
const Slice2DRenderer::DrawList& Slice2DRenderer::channelPlanes(int axis, bool descending,
                                                                int planes, int slabPlanes) {
  const std::string key = "channels " + std::to_string(axis) + (descending ? "-" : "+") +
                          std::to_string(planes) + "/" + std::to_string(slabPlanes);
  auto it = drawLists_.find(key);
  if (it != drawLists_.end()) return it->second;
  const glm::ivec2 a = sliceTileAxes(axis);
  const glm::dvec3 extent = volume_.extent();
  const double margin = 2.0 * (slabPlanes - 1) * extent[axis] / planes;
  const int slabs = (planes + slabPlanes - 1) / slabPlanes;
  std::vector<float> v;
  std::vector<std::uint16_t> indices;
  constexpr int corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int m = 0; m < slabs; ++m) {
    const int k = m * slabPlanes;
    const int s = descending ? planes - 1 - k : k;
    glm::dvec3 pos(0.0);
    pos[axis] = ((s + 0.5) / planes - 0.5) * extent[axis];
    for (const auto& c : corners) {
      pos[a.x] = (c[0] - 0.5) * extent[a.x] + (c[0] * 2 - 1) * margin;
      pos[a.y] = (c[1] - 0.5) * extent[a.y] + (c[1] * 2 - 1) * margin;
      v.insert(v.end(), {static_cast<float>(pos.x), static_cast<float>(pos.y),
                         static_cast<float>(pos.z), 0.0f, 0.0f, static_cast<float>(m), 0.0f});
    }
    for (int i : {0, 1, 2, 0, 2, 3}) indices.push_back(static_cast<std::uint16_t>(m * 4 + i));
  }
  DrawList list;
  list.gapRatio = static_cast<double>(plans_[axis].slices) / planes;
  list.ranges.push_back({0, 0, static_cast<int>(indices.size())});
  list.vertices =
      gpu::Buffer::create(context_.ledger(), "slice2d channel planes", gpu::BufferKind::Vertices,
                          v.size() * sizeof(float), v.data(), gpu::BufferUsage::Static);
  list.indices = gpu::Buffer::create(
      context_.ledger(), "slice2d channel draw order", gpu::BufferKind::Indices16,
      indices.size() * sizeof(std::uint16_t), indices.data(), gpu::BufferUsage::Static);
  return drawLists_.emplace(key, std::move(list)).first->second;
}

int Slice2DRenderer::channelPlaneCount(const RenderSettings& settings, int axis) const {
  constexpr int kMaxPlanes = 65536 / 4;  // 16-bit indices, four vertices a plane
  const double n =
      requestedSlices_ > 0
          ? requestedSlices_
          : std::ceil(volume_.extent()[axis] / sampleDistance(settings, volume_.spacing()) - 1e-9);
  if (n > kMaxPlanes) {
    throw InputError("a step of " + std::to_string(settings.stepVoxels) + " voxels needs " +
                     std::to_string(static_cast<long long>(n)) + " planes, more than " +
                     std::to_string(kMaxPlanes) + "; use a larger --step or --slices");
  }
  return std::max(1, static_cast<int>(n));
}

void Slice2DRenderer::uploadStack(int axis) {
  const auto t0 = std::chrono::steady_clock::now();
  const SliceAtlasPlan& p = plans_[axis];
  const bool pre = options_.classification == SliceClassification::Pre;
  const gpu::TexelFormat format =
      pre || shadedStacks_ ? gpu::rgba8For(context_.caps().api) : gpu::r8For(context_.caps().api);
  const bool recreate = atlases_[axis].size() != static_cast<std::size_t>(p.atlases);
  if (recreate) atlases_[axis].clear();
  // Filled and uploaded a band (one row of tiles) at a time: the host copy
  // is a band, not an atlas. A whole-atlas copy (64 MiB for a 256^3 stack in
  // RGBA) is past glibc's mmap threshold, so each TF change paid a fresh
  // mapping's page faults (668 ms instead of 82 ms for three 256^3 stacks).
  std::vector<std::uint8_t> band;
  for (int i = 0; i < p.atlases; ++i) {
    if (recreate) {
      atlases_[axis].push_back(gpu::Texture::create2D(
          context_.ledger(), "slice2d atlas " + std::string(1, "xyz"[axis]) + std::to_string(i),
          format, p.atlasSize.x, p.atlasSize.y));
      if (options_.classification == SliceClassification::Palette) {
        atlases_[axis].back().setFilter(gpu::Filter::Nearest);
      }
    }
    gpu::Texture& atlas = atlases_[axis][static_cast<std::size_t>(i)];
    for (int b = 0; b < p.bands(); ++b) {
      if (shadedStacks_) {
        stacks_->fillShadingAtlasBand(p, i, b, band);
      } else {
        stacks_->fillAtlasBand(p, i, b, pre ? palette8_.data() : nullptr, band);
      }
      atlas.updateRegion({0, b * p.tile.y, 0}, {p.atlasSize.x, p.bandRows(b), 1}, band.data());
    }
  }
  gpu::finish();
  ++stackUploads_;
  lastStackUploadMs_ = msSince(t0);
}

void Slice2DRenderer::recreateStackTextures() {
  for (int axis = 0; axis < 3; ++axis) {
    if (atlases_[axis].empty()) continue;
    atlases_[axis].clear();
    uploadStack(axis);
  }
}

void Slice2DRenderer::updateClassification(const RenderSettings& settings) {
  const ValueRange w = volume_.window();
  std::ostringstream key;
  key.precision(17);
  key << settings.opacityScale << '|' << w.min << '|' << w.max << '|' << settings.nearest << '|'
      << tf_.toJson();
  if (key.str() == classificationKey_) return;
  classificationKey_ = key.str();
  ++classificationUpdates_;
  const double ds0 = baseDistance();
  switch (options_.classification) {
    case SliceClassification::Post:
      // Nearest (labels): one entry per 8-bit value, never mixed with a neighbour's.
      table_.upload(context_, tf_.bake(settings.nearest ? 256 : 4096, ds0, settings.opacityScale),
                    "slice2d transfer function");
      return;
    case SliceClassification::Palette:
    case SliceClassification::Pre: {
      std::vector<float> palette = tf_.bake(256, ds0, settings.opacityScale);
      for (std::size_t i = 0; i < palette.size(); i += 4) {
        for (std::size_t c = 0; c < 3; ++c) palette[i + c] *= palette[i + 3];
      }
      if (options_.classification == SliceClassification::Palette) {
        table_.upload(context_, palette, "slice2d palette");
        return;
      }
      palette8_.resize(palette.size());
      for (std::size_t i = 0; i < palette.size(); ++i) {
        palette8_[i] =
            static_cast<std::uint8_t>(std::lround(std::clamp(palette[i], 0.0f, 1.0f) * 255.0f));
      }
      // The CPU classification: every resident slice re-created.
      for (int axis = 0; axis < 3; ++axis) {
        if (!atlases_[axis].empty()) uploadStack(axis);
      }
      return;
    }
  }
}

std::vector<gpu::ShaderPart> Slice2DRenderer::vertexParts() const {
  return {gpu::shaderPreamble(context_.caps().api, false, {}),
          gpu::embeddedShaderPart("render/slice2d.vert.glsl")};
}

std::vector<gpu::ShaderPart> Slice2DRenderer::fragmentParts(const RenderSettings& settings) const {
  if (options_.channels) return channelFragmentParts(settings);
  std::vector<std::string> defines;
  if (options_.classification == SliceClassification::Pre) defines.push_back("CLASSIFY_PRE 1");
  if (options_.classification == SliceClassification::Palette) {
    defines.push_back("CLASSIFY_PALETTE 1");
  }
  if (settings.mode == RenderMode::Mip) defines.push_back("MODE_MIP 1");
  addShadingDefines(settings, defines);
  addClippingDefines(settings, defines);
  if (settings.nearest) defines.push_back("NEAREST 1");
  return {gpu::shaderPreamble(context_.caps().api, true, defines),
          gpu::embeddedShaderPart("render/classify.glsl"),
          gpu::embeddedShaderPart("render/shading.glsl"),
          gpu::embeddedShaderPart("render/clipping.glsl"),
          gpu::embeddedShaderPart("render/slice_opacity.glsl"),
          gpu::embeddedShaderPart("render/slice2d.frag.glsl")};
}

// Channel frames: the layout's seam (sampleChannels and its uniforms), the
// TF table and render/channels.glsl, then the stack's channel fragment.
// Shading and clipping are not applied to channel frames (docs/channels.md).
std::vector<gpu::ShaderPart> Slice2DRenderer::channelFragmentParts(
    const RenderSettings& settings) const {
  std::vector<std::string> defines;
  if (settings.mode == RenderMode::Mip) defines.push_back("MODE_MIP 1");
  defines.push_back("SLAB_PLANES " + std::to_string(slabPlanesFor(settings)));
  // Slabs dither their 8-bit rounding (slice2d_channels.frag.glsl).
  if (settings.mode != RenderMode::Mip && accumulator_.roundsTo8Bits()) {
    defines.push_back("DITHER_8BIT 1");
  }
  std::vector<gpu::ShaderPart> parts = {gpu::shaderPreamble(context_.caps().api, true, defines)};
  for (gpu::ShaderPart& part : options_.channels->seamParts()) parts.push_back(std::move(part));
  for (const char* file : {"render/classify.glsl", "render/channels.glsl",
                           "render/slice_opacity.glsl", "render/slice2d_channels.frag.glsl"}) {
    parts.push_back(gpu::embeddedShaderPart(file));
  }
  return parts;
}

std::vector<gpu::ShaderPart> Slice2DRenderer::channelResolveParts() const {
  std::vector<gpu::ShaderPart> frag = {gpu::shaderPreamble(context_.caps().api, true, {})};
  for (gpu::ShaderPart& part : options_.channels->seamParts()) frag.push_back(std::move(part));
  for (const char* file : {"render/classify.glsl", "render/channels.glsl",
                           "render/slice_channels_resolve.frag.glsl"}) {
    frag.push_back(gpu::embeddedShaderPart(file));
  }
  return frag;
}

const gpu::Program& Slice2DRenderer::channelResolveProgram() {
  return programs_.get("channel maxima resolve", [&] {
    const gpu::ApiLevel api = context_.caps().api;
    return gpu::Program::build("slice2d channel maxima resolve",
                               {gpu::shaderPreamble(api, false, {}),
                                gpu::embeddedShaderPart("render/fullscreen.vert.glsl")},
                               channelResolveParts());
  });
}

const gpu::Program& Slice2DRenderer::programFor(const RenderSettings& settings) {
  if (options_.channels) {
    const std::string key = std::string("channels") +
                            (settings.mode == RenderMode::Mip ? "|mip" : "") + "|slab " +
                            std::to_string(slabPlanesFor(settings));
    return programs_.get(key, [&] {
      return gpu::Program::build("slice2d(" + key + ")", vertexParts(), fragmentParts(settings));
    });
  }
  const std::string key =
      std::string(sliceClassificationName(options_.classification)) +
      (settings.mode == RenderMode::Mip ? "|mip" : "") + (shadingActive(settings) ? "|shade" : "") +
      (settings.clipping.active() ? "|clip" : "") + (settings.nearest ? "|nearest" : "");
  return programs_.get(key, [&] {
    return gpu::Program::build("slice2d(" + key + ")", vertexParts(), fragmentParts(settings));
  });
}

void Slice2DRenderer::prepare(const Camera& camera, const RenderSettings& settings) {
  if (settings.mode == RenderMode::MinIp || settings.mode == RenderMode::Average) {
    throw InputError(
        "slice2d blends composite and MIP only; MinIP and the average need the ray "
        "caster (--technique raycast)");
  }
  if (settings.mode == RenderMode::Mip && options_.classification != SliceClassification::Post) {
    throw InputError(
        "MIP by axis-aligned slicing needs --classify post (the maximum of "
        "classified colours is not the colour of the maximum)");
  }
  if (options_.channels) {
    if (options_.classification != SliceClassification::Post) {
      throw InputError(
          "slice2d draws channels post-classified (--classify post): pre and palette classify "
          "one volume's values");
    }
    updateClassification(settings);
    programFor(settings);
    return;
  }
  const bool shade = shadingActive(settings);
  if (shade && options_.classification != SliceClassification::Post) {
    throw InputError(
        "shading by axis-aligned slicing needs --classify post (the gradient is taken from "
        "the slices' values)");
  }
  if (shade != shadedStacks_) {
    // Shaded stacks carry each slice's neighbours (SliceStacks::fillShadingAtlasBand).
    for (auto& list : atlases_) list.clear();
    shadedStacks_ = shade;
  }
  // Classification first: pre-classified stacks are created from its palette.
  updateClassification(settings);
  const int axis = stackAxisFor(camera);
  if (options_.currentStackOnly) {
    if (atlases_[axis].empty()) {
      for (auto& list : atlases_) list.clear();  // one stack at a time: a third of the memory
      uploadStack(axis);
    }
  } else {
    for (int a = 0; a < 3; ++a) {
      if (atlases_[a].empty()) uploadStack(a);
    }
  }
  programFor(settings);
}

void Slice2DRenderer::renderFrame(const Camera& camera, const RenderSettings& settings, int width,
                                  int height) {
  prepare(camera, settings);
  const int axis = stackAxisFor(camera);
  lastAxis_ = axis;
  const SliceAtlasPlan& plan = plans_[axis];
  const int slices = options_.channels      ? channelPlaneCount(settings, axis)
                     : requestedSlices_ > 0 ? std::min(requestedSlices_, plan.slices)
                                            : plan.slices;
  lastSlicesDrawn_ = slices;
  lastSlabPlanes_ = slabPlanesFor(settings);
  const glm::dvec3 forward = -camera.basis()[2];
  // Front to back: looking towards +axis, the low slices are nearest.
  const DrawList& list = options_.channels
                             ? channelPlanes(axis, forward[axis] < 0.0, slices, lastSlabPlanes_)
                             : drawList(axis, forward[axis] < 0.0, slices);

  const bool shade = !options_.channels && shadingActive(settings);
  accumulator_.begin(width, height, settings.mode);
  const gpu::Program& prog = programFor(settings);
  prog.use();
  const double farPlane = glm::length(camera.eye()) + glm::length(volume_.extent());
  prog.set("u_worldToClip",
           glm::mat4(sliceViewToClip(camera, static_cast<double>(width) / height, farPlane) *
                     sliceWorldToView(camera)));
  prog.set("u_tileSize", glm::vec2(plan.tile));
  prog.set("u_atlasInvSize", glm::vec2(1.0 / plan.atlasSize.x, 1.0 / plan.atlasSize.y));
  glm::vec3 axisVector(0.0f);
  axisVector[axis] = 1.0f;
  prog.set("u_axis", axisVector);
  prog.set("u_gap", static_cast<float>(volume_.spacing()[axis] * list.gapRatio / baseDistance()));
  prog.set("u_eye", glm::vec3(camera.eye()));
  prog.set("u_forward", glm::vec3(forward));
  prog.set("u_ortho", camera.projection == Projection::Orthographic ? 1.0f : 0.0f);
  if (options_.channels) {
    prog.set("u_invExtent", glm::vec3(1.0 / volume_.extent()));
    // A slab's next plane is this far along the stack axis (front to back).
    prog.set("u_planeStep", static_cast<float>((forward[axis] < 0.0 ? -1.0 : 1.0) *
                                               volume_.extent()[axis] / slices));
    const int unit = options_.channels->bindSeam(prog, 0);
    table_.texture().bind(unit);
    prog.set("u_tf", unit);
    prog.set("u_tfSize", static_cast<float>(table_.entries()));
    if (settings.mode == RenderMode::Mip) {
      drawChannelMaxima(prog, axis, list, settings);
    } else {
      drawStack(prog, axis, list);
      accumulator_.resolve(settings, &table_.texture(), table_.entries());
    }
    return;
  }
  prog.set("u_atlas", 0);
  if (settings.clipping.active()) {
    setClippingUniforms(prog, settings, camera, volume_.extent());
    prog.set("u_invExtent", glm::vec3(1.0 / volume_.extent()));
  }
  if (shade) {
    // The stacks hold the window's normalised value quantised: one per stored unit.
    setShadingUniforms(prog, settings, camera, 1.0, volume_.extent(), volume_.spacing());
    const glm::ivec2 a = sliceTileAxes(axis);
    glm::vec3 u(0.0f), v(0.0f);
    u[a.x] = 1.0f;
    v[a.y] = 1.0f;
    prog.set("u_tileAxisU", u);
    prog.set("u_tileAxisV", v);
    prog.set("u_halfDims",
             glm::vec3(volume_.dims()[a.x], volume_.dims()[a.y], volume_.dims()[axis]) * 0.5f);
  }
  if (options_.classification == SliceClassification::Post) {
    table_.texture().bind(1);
    prog.set("u_tf", 1);
    prog.set("u_tfSize", static_cast<float>(table_.entries()));
  } else if (options_.classification == SliceClassification::Palette) {
    table_.texture().bind(1);
    prog.set("u_palette", 1);
  }

  drawStack(prog, axis, list);
  accumulator_.resolve(settings, &table_.texture(), table_.entries());
}

// The list's planes front to back; each atlas bound in turn (channel frames
// sample the layout and bind none).
void Slice2DRenderer::drawStack(const gpu::Program& prog, int axis, const DrawList& list) {
  const int tileAttribute = prog.attributeLocation("a_tile");
  for (const DrawRange& r : list.ranges) {
    if (!options_.channels) atlases_[axis][static_cast<std::size_t>(r.atlas)].bind(0);
    gpu::drawIndexed16(gpu::Primitive::Triangles,
                       list.vertices.id() != 0 ? list.vertices : vertices_[axis], list.indices,
                       {{0, 3, 0}, {tileAttribute, 4, 3}}, kFloatsPerVertex, r.count, r.firstIndex);
  }
}

// Channel maxima (docs/channels.md) as slice3d takes them: the stack twice,
// channels 0-3 into the accumulation target, 4-5 and the hit flag into a
// second (ES 2 has no multiple render targets), then the resolve that
// colours them (render/slice_channels_resolve.frag.glsl).
void Slice2DRenderer::drawChannelMaxima(const gpu::Program& prog, int axis, const DrawList& list,
                                        const RenderSettings& settings) {
  for (int group = 0; group < 2; ++group) {
    if (group == 1) accumulator_.beginSecond(settings.mode);
    prog.set("u_channelGroup", static_cast<float>(group));
    drawStack(prog, axis, list);
  }
  const gpu::Program& resolve = channelResolveProgram();
  resolve.use();
  const int unit = options_.channels->bindSeam(resolve, 0);
  accumulator_.resolveWith(resolve, unit, settings);
}

// ---- The Technique interface and the registry's entry.

const gpu::Texture& Slice2DRenderer::render(const Camera& camera, const RenderSettings& settings,
                                            int width, int height, double viewAspect) {
  const glm::ivec2 size = sliceTargetSize(width, height, viewAspect);
  renderFrame(camera, settings, size.x, size.y);
  return colorTexture();
}

TechniqueReport Slice2DRenderer::report() const {
  TechniqueReport r;
  if (options_.channels) {
    r.note = "slice2d: " + std::to_string(lastSlicesDrawn_) + " " +
             (lastAxis_ >= 0 ? std::string(1, "xyz"[lastAxis_]) : std::string("?")) +
             " planes of the channel layout drawn";
    if (lastSlabPlanes_ > 1) {
      r.note += " in " +
                std::to_string((lastSlicesDrawn_ + lastSlabPlanes_ - 1) / lastSlabPlanes_) +
                " slabs of " + std::to_string(lastSlabPlanes_);
    }
    r.note += ", accumulation " + accumulationFormat();
    return r;
  }
  r.storage = "slice-stacks";
  r.storageReason = "three axis-aligned stacks";
  if (lastAxis_ >= 0) {
    r.storageReason += "; drawn: " + std::string(1, "xyz"[lastAxis_]) + " stack, " +
                       plans_[lastAxis_].describe() + ", " +
                       sliceClassificationName(options_.classification) + "-classified";
  }
  r.storageBytes = stackTextureBytes();
  r.note = "slice2d: " + std::to_string(lastSlicesDrawn_) + " slices drawn, accumulation " +
           accumulationFormat();
  return r;
}

TechniqueRequirements Slice2DRenderer::requirements(const gpu::DeviceLimits&, glm::ivec3,
                                                    const TechniqueOptions&) {
  TechniqueRequirements r;
  r.textureUnits = 2;  // an atlas and the TF table or palette
  r.ownStorage = "it stores its own slice stacks";
  return r;
}

std::unique_ptr<Slice2DRenderer> Slice2DRenderer::create(const TechniqueSetup& s) {
  Slice2DOptions options;
  options.classification = parseSliceClassification(s.options.classify);
  options.currentStackOnly = s.options.currentStackOnly;
  options.maxTextureSize = s.limits.max2DTextureSize;
  options.halfFloatAccumulation = s.limits.halfFloatRenderTargets;
  if (s.layout && s.layout->drawsChannels()) options.channels = s.layout;
  auto slicer = std::make_unique<Slice2DRenderer>(s.context, s.volume, options);
  slicer->setSliceCount(s.options.slices);
  return slicer;
}

TechniqueEntry Slice2DRenderer::registration() {
  return {
      .name = "slice2d",
      .summary = "axis-aligned slice stacks",
      .drawsChannels = true,
      .drawsChannelBricks = true,
      .requirements = &Slice2DRenderer::requirements,
      .create = [](const TechniqueSetup& s) -> std::unique_ptr<Technique> { return create(s); }};
}

}  // namespace tessera::render
