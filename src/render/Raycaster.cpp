#include "tessera/render/Raycaster.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/packing.hpp>

#include "render/FramebufferImage.h"
#include "render/SampleParts.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/Draw.h"
#include "tessera/render/ClippingUniforms.h"
#include "tessera/render/ShadingUniforms.h"

namespace tessera::render {

Raycaster::Raycaster(gpu::GlContext& context, const Volume& volume, const layout::Layout& layout)
    : context_(context),
      volume_(volume),
      layout_(layout),
      tf_(TransferFunction::preset("grey")),
      gradient_(context, volume, layout, kOwnTextureUnits),
      fusion_(context) {
  triangle_ = gpu::FullscreenTriangle(context.ledger());
  // The value blocks are built on first use (or by setSkipBlockSize): the
  // default 8 over level 0 of an 8192^3 brick source would be 1024^3 blocks
  // (8 GiB) before the caller's larger block size replaced it.
  blocksVersion_ = ~std::uint64_t(0);
}

Raycaster::~Raycaster() = default;

void Raycaster::setTransferFunction(const TransferFunction& tf) {
  tf_ = tf;
  lookupKey_.clear();
}

void Raycaster::setSkipBlockSize(int voxels) {
  if (voxels < 0)
    throw InputError("empty-space block size must be >= 0, got " + std::to_string(voxels));
  blockSize_ = voxels;
  blocks_ = voxels > 0 ? layout_.valueBlocks(voxels) : layout::ValueBlocks();
  blocksVersion_ = layout_.contentVersion();
  blockTexture_ = gpu::Texture();
  lookupKey_.clear();
  blocksKey_.clear();
}

// A streamed layout (bricks) changed what it samples: its value blocks
// again, classified at the next lookup update. The TF's tables stay, and
// so does the blocks' texture (the same grid: updated in place), so that a
// refinement's rebuild is the blocks' work alone (and in a browser no new
// texture's allocation checks).
void Raycaster::refreshValueBlocks() {
  layout::ValueBlocks blocks = layout_.valueBlocks(blockSize_);
  if (blocks.blockCount() != blocks_.blockCount()) blockTexture_ = gpu::Texture();
  blocks_ = std::move(blocks);
  blocksVersion_ = layout_.contentVersion();
  blocksKey_.clear();
}

void Raycaster::setLutSize(int entries) {
  if (entries != 256 && entries != 4096) {
    throw InputError("transfer-function table size must be 256 or 4096, got " +
                     std::to_string(entries));
  }
  lutSize_ = entries;
  lut_ = gpu::LookupTexture();
  lookupKey_.clear();
}

std::uint64_t Raycaster::ownTextureBytes() const {
  std::uint64_t spares = 0;
  for (const gpu::Framebuffer& f : spareTargets_) spares += f.color().bytes();
  return lut_.bytes() + preint_.bytes() + blockTexture_.bytes() + target_.color().bytes() + spares +
         gradient_.bytes() + fusion_.bytes();
}

void Raycaster::setPreintegrationEntries(int entries) {
  if (entries < 16 || entries > 1024) {
    throw InputError("pre-integration table size must be 16..1024 entries per axis, got " +
                     std::to_string(entries));
  }
  preintEntries_ = entries;
  lookupKey_.clear();
}

bool Raycaster::logTransmittance(const RenderSettings& settings) const {
  // Unlit adaptive composite frames: a stretch of m base steps then costs
  // one exp2 instead of a pow, and the accumulated transmittance's log2,
  // which the steps grow by, is a running sum instead of a log2 per
  // iteration (1.12x post-classified, 1.09x pre-integrated at step 1 on
  // llvmpipe). Lit frames gained nothing (post-classified) or lost 6 %
  // (pre-integrated), and gradient opacity scales opacity itself. The
  // 256-entry table keeps the linear lookup of opacity the reference takes;
  // an RGBA8 pre-integration table cannot hold negative numbers.
  if (blockSize_ == 0 || !usesAdaptiveSampling(settings) || litSamples(settings)) return false;
  return usesPreintegration(settings) ? preint_.floatTexels(context_) : lutSize_ >= 4096;
}

void Raycaster::updateLookup(const RenderSettings& settings, double sampleDistance) {
  if (blockSize_ > 0 && layout_.contentVersion() != blocksVersion_) refreshValueBlocks();
  const ValueRange w = volume_.window();
  const bool pre = usesPreintegration(settings);
  const bool adaptive = blockSize_ > 0 && usesAdaptiveSampling(settings);
  const bool logT = logTransmittance(settings);
  std::ostringstream key;
  key.precision(17);
  key << sampleDistance << '|' << settings.opacityScale << '|' << w.min << '|' << w.max << '|'
      << lutSize_ << '|' << blockSize_ << '|' << pre << '|' << preintEntries_ << '|' << adaptive
      << '|' << adaptiveTolerance(settings) << '|' << settings.sampling.maxMultiplier << '|' << logT
      << '|' << tf_.toJson();
  if (key.str() != lookupKey_) {
    lookupKey_ = key.str();
    updateTables(settings, sampleDistance, pre, logT);
  }
  // The blocks are classified for these tables and this content.
  if (blocksKey_ == lookupKey_) return;
  blocksKey_ = lookupKey_;
  classifyBlocks(settings, sampleDistance, pre, adaptive);
}

void Raycaster::updateTables(const RenderSettings& settings, double sampleDistance, bool pre,
                             bool logT) {
  // Composite with pre-integration classifies segments through the 2D table
  // and needs no 1D one; everything else samples the 1D table.
  if (pre) {
    preint_.setLogTransmittance(logT);
    preint_.update(context_, tf_, settings.opacityScale, sampleDistance, preintEntries_);
  } else {
    lutValues_ = tf_.bake(lutSize_, sampleDistance, settings.opacityScale);
    if (logT) toLog2Transmittance(lutValues_);
    uploadLut();
  }
}

void Raycaster::classifyBlocks(const RenderSettings& settings, double sampleDistance, bool pre,
                               bool adaptive) {
  const ValueRange w = volume_.window();
  occupiedFraction_ = 1.0;
  stepGrid_ = StepGrid();
  if (blockSize_ == 0) return;
  // Per block: visible at all (and with adaptive sampling its step
  // multiplier) for the table the ray caster samples (AdaptiveSteps.h), and
  // the largest normalised value for MIP.
  // The tolerance this frame uses (lit frames have their own).
  Sampling sampling = settings.sampling;
  sampling.tolerance = adaptiveTolerance(settings);
  const std::vector<std::uint8_t> codes =
      classifyStepBlocks(blocks_.mins(), blocks_.maxs(), w, tf_, settings.opacityScale,
                         sampleDistance, pre ? preintEntries_ : lutSize_, sampling, adaptive);
  const double ww = w.max - w.min;
  std::vector<std::uint8_t> cells(codes.size() * 4, 0);
  std::size_t occupiedCount = 0;
  for (std::size_t b = 0; b < codes.size(); ++b) {
    const double nhi = std::clamp((blocks_.maxs()[b] - w.min) / ww, 0.0, 1.0);
    occupiedCount += codes[b] > 0 ? 1 : 0;
    // Rounded up so that "block max <= current max" never skips a larger sample.
    cells[b * 4 + 1] = static_cast<std::uint8_t>(std::min(255.0, std::ceil(nhi * 255.0)));
    cells[b * 4 + 2] = codes[b];  // the step allowance (AdaptiveSteps.h)
  }
  stepGrid_ = {.dims = volume_.dims(),
               .blockSize = blockSize_,
               .count = blocks_.blockCount(),
               .codes = codes,
               .emptyDistance = {}};
  stepGrid_.measureEmptySpace();
  const glm::ivec3 count = stepGrid_.count;
  for (int z = 0, b = 0; z < count.z; ++z) {
    for (int y = 0; y < count.y; ++y) {
      for (int x = 0; x < count.x; ++x, ++b) {
        const auto i = static_cast<std::size_t>(b) * 4;
        cells[i] = stepGrid_.distance({x, y, z});
        cells[i + 3] = stepGrid_.aheadCode({x, y, z});
      }
    }
  }
  occupiedFraction_ = static_cast<double>(occupiedCount) / static_cast<double>(codes.size());
  uploadBlocks(cells);
}

void Raycaster::uploadLut() {
  lut_.upload(context_, lutValues_, "transfer function");
}

void Raycaster::uploadBlocks(const std::vector<std::uint8_t>& cells) {
  const glm::ivec3 c = blocks_.blockCount();
  if (context_.caps().api == gpu::ApiLevel::Gles3) {
    // One texelFetch per lookup: measurably cheaper per sample than the
    // mosaic's address arithmetic (docs/benchmarks.md, Ray casting).
    if (blockTexture_.id() == 0) {
      blockTexture_ = gpu::Texture::create3D(context_.ledger(), "empty-space blocks",
                                             gpu::TexelFormat::RGBA8, c.x, c.y, c.z, cells.data());
      blockTexture_.setFilter(gpu::Filter::Nearest);
    } else {
      blockTexture_.update(cells.data());
    }
    return;
  }
  // ES 2: the grid's z-slices side by side in one RGBA8 2D texture.
  const int maxSize = context_.caps().max2DTextureSize;
  const int tilesX = std::max(1, std::min(c.z, maxSize / c.x));
  const int tilesY = (c.z + tilesX - 1) / tilesX;
  if (tilesY * c.y > maxSize) {
    throw GpuError("empty-space grid " + std::to_string(c.x) + "x" + std::to_string(c.y) + "x" +
                   std::to_string(c.z) + " does not fit a " + std::to_string(maxSize) +
                   " texture; use a larger --skip-block");
  }
  blockTilesX_ = tilesX;
  blockTexSize_ = glm::ivec2(tilesX * c.x, tilesY * c.y);
  std::vector<std::uint8_t> texels(static_cast<std::size_t>(blockTexSize_.x) * blockTexSize_.y * 4,
                                   0);
  for (int z = 0; z < c.z; ++z) {
    const int ox = (z % tilesX) * c.x, oy = (z / tilesX) * c.y;
    for (int y = 0; y < c.y; ++y) {
      for (int x = 0; x < c.x; ++x) {
        const std::size_t b = blocks_.index(x, y, z);
        const std::size_t t = (static_cast<std::size_t>(oy + y) * blockTexSize_.x + ox + x) * 4;
        for (int ch = 0; ch < 4; ++ch) texels[t + ch] = cells[b * 4 + ch];
      }
    }
  }
  if (blockTexture_.id() == 0) {
    blockTexture_ = gpu::Texture::create2D(context_.ledger(), "empty-space blocks",
                                           gpu::TexelFormat::Rgba8Unsized, blockTexSize_.x,
                                           blockTexSize_.y, texels.data());
    blockTexture_.setFilter(gpu::Filter::Nearest);
  } else {
    blockTexture_.update(texels.data());
  }
}

std::vector<std::string> Raycaster::definesFor(const RenderSettings& settings) const {
  std::vector<std::string> defines;
  if (settings.mode == RenderMode::Mip) defines.push_back("MODE_MIP 1");
  if (settings.mode == RenderMode::MinIp) defines.push_back("MODE_MINIP 1");
  if (settings.mode == RenderMode::Average) defines.push_back("MODE_AVERAGE 1");
  // The block grid knows which blocks are transparent and their maxima: it
  // serves composite and MIP; MinIP and the average need every sample.
  const bool skippable = settings.mode == RenderMode::Composite || settings.mode == RenderMode::Mip;
  if (blockSize_ > 0 && skippable && !fusion_.active()) {
    defines.push_back("EMPTY_SPACE_SKIPPING 1");
  }
  // Fewer samples (docs/sampling.md): both for composite only; adaptive steps
  // live in the block grid.
  if (usesPreintegration(settings)) defines.push_back("PREINTEGRATED 1");
  // The brick walk reads the layout's page once per brick cell a ray
  // enters; a pre-integrated segment's front may lie in the cell before, so
  // it samples through the page per sample.
  if (layout_.walksBricks() && !usesPreintegration(settings)) {
    defines.push_back("LAYOUT_BRICK_WALK 1");
  }
  if (blockSize_ > 0 && usesAdaptiveSampling(settings)) {
    defines.push_back("ADAPTIVE_SAMPLING 1");
    if (settings.sampling.opacityGrowth) defines.push_back("OPACITY_GROWTH 1");
  }
  addShadingDefines(settings, defines);
  gradient_.addDefines(settings, defines);
  addClippingDefines(settings, defines);
  if (settings.nearest) defines.push_back("NEAREST 1");
  // The 4096-entry table is read at its nearest entry (render/classify.glsl);
  // a 256-entry one keeps the linear lookup.
  if (lutSize_ >= 4096) defines.push_back("TF_NEAREST_ENTRY 1");
  if (logTransmittance(settings)) defines.push_back("LOG_TRANSMITTANCE 1");
  fusion_.addDefines(defines);
  defines.push_back("MAX_STEPS " + std::to_string(settings.maxSteps));
  return defines;
}

std::vector<gpu::ShaderPart> Raycaster::vertexParts() const {
  return {gpu::shaderPreamble(context_.caps().api, false, {}),
          gpu::embeddedShaderPart("render/fullscreen.vert.glsl")};
}

std::vector<gpu::ShaderPart> Raycaster::fragmentParts(const RenderSettings& settings) const {
  // The technique composed from parts (DESIGN.md): rays, the layout seam
  // (sampleVolume() and its gradient), the shared classified sample and
  // compositing, and the marching loop.
  std::vector<gpu::ShaderPart> parts = {
      gpu::shaderPreamble(context_.caps().api, true, definesFor(settings)),
      gpu::embeddedShaderPart("render/camera_ray.glsl")};
  fusion_.addParts(parts);
  addSampleParts(parts, gradient_, layout_);
  parts.push_back(gpu::embeddedShaderPart("render/composite.glsl"));
  parts.push_back(gpu::embeddedShaderPart("render/raycast.frag.glsl"));
  return parts;
}

const gpu::Program& Raycaster::programFor(const RenderSettings& settings) {
  std::string key = layout_.name();
  for (const auto& d : definesFor(settings)) key += "|" + d;
  return programs_.get(key, [&] {
    return gpu::Program::build("raycast(" + key + ")", vertexParts(), fragmentParts(settings));
  });
}

namespace {

// A fused frame takes every sample post-classified (docs/fusion.md): the
// fused volume is mixed into classifiedSample, which neither segments nor
// the block walk's adaptive steps take.
bool dropsSampling(bool fused, const RenderSettings& settings) {
  return fused && (settings.sampling.preintegrate || settings.sampling.adaptive);
}

RenderSettings everySample(RenderSettings settings) {
  settings.sampling = Sampling();
  return settings;
}

}  // namespace

void Raycaster::prepare(const RenderSettings& settings) {
  if (dropsSampling(fusion_.active(), settings)) return prepare(everySample(settings));
  const glm::dvec3 spacing = volume_.spacing();
  const double ds = sampleDistance(settings, spacing);
  updateLookup(settings, isProjection(settings.mode) ? tf_.opacityUnitLength : ds);
  gradient_.prepare(settings);
  programFor(settings);
}

void Raycaster::renderFrame(const Camera& camera, const RenderSettings& settings, int width,
                            int height) {
  if (dropsSampling(fusion_.active(), settings)) {
    return renderFrame(camera, everySample(settings), width, height);
  }
  // A streamed layout (bricks) changed what it samples: new value blocks.
  if (blockSize_ > 0 && layout_.contentVersion() != blocksVersion_) refreshValueBlocks();
  if (width <= 0 || height <= 0 || width > context_.caps().maxRenderbufferSize ||
      height > context_.caps().maxRenderbufferSize) {
    throw InputError("image size " + std::to_string(width) + "x" + std::to_string(height) +
                     " is outside 1.." + std::to_string(context_.caps().maxRenderbufferSize));
  }
  if (settings.maxSteps <= 0 || settings.maxSteps > 65536) {
    throw InputError("max steps must be 1..65536, got " + std::to_string(settings.maxSteps));
  }
  const glm::dvec3 spacing = volume_.spacing();
  const double ds = sampleDistance(settings, spacing);
  // MIP shows one classified sample, so its table is not distance-corrected
  // (correcting for one unit length leaves opacity as it is).
  updateLookup(settings, isProjection(settings.mode) ? tf_.opacityUnitLength : ds);
  gradient_.prepare(settings);

  useTarget(width, height);
  target_.bind();
  const gpu::Program& prog = programFor(settings);
  prog.use();

  const glm::dmat3 b = camera.basis();
  prog.set("u_eye", glm::vec3(camera.eye()));
  prog.set("u_right", glm::vec3(b[0]));
  prog.set("u_up", glm::vec3(b[1]));
  prog.set("u_forward", glm::vec3(-b[2]));
  prog.set("u_tanHalfFov",
           static_cast<float>(std::tan(0.5 * camera.fovYDeg * glm::pi<double>() / 180.0)));
  prog.set("u_orthoHalfHeight", static_cast<float>(camera.orthoHalfHeight()));
  prog.set("u_aspect", static_cast<float>(viewAspect_ > 0.0 ? viewAspect_
                                                            : static_cast<double>(width) / height));
  prog.set("u_ortho", camera.projection == Projection::Orthographic ? 1 : 0);
  prog.set("u_viewport", glm::vec2(width, height));
  prog.set("u_extent", glm::vec3(volume_.extent()));
  prog.set("u_step", static_cast<float>(ds));
  prog.set("u_maxSteps", static_cast<float>(settings.maxSteps));
  prog.set("u_ert", static_cast<float>(settings.ertThreshold));
  prog.set("u_jitter", settings.jitter ? 1.0f : 0.0f);
  prog.set("u_background", glm::vec4(settings.background));

  // normalised = (raw - wmin) / (wmax - wmin), raw = scale * stored + offset.
  const layout::ValueMapping m = layout_.rawFromStored();
  const ValueRange w = volume_.window();
  const double ww = w.max - w.min;
  prog.set("u_valueScale", static_cast<float>(m.scale / ww));
  prog.set("u_valueBias", static_cast<float>((m.offset - w.min) / ww));
  setShadingUniforms(prog, settings, camera, m.scale / ww, volume_.extent(), spacing);
  setClippingUniforms(prog, settings, camera, volume_.extent());
  if (settings.nearest) prog.set("u_sampleDims", glm::vec3(volume_.dims()));

  int unit = layout_.bindSeam(prog, 0);
  unit += gradient_.bind(prog, unit, settings);
  if (usesPreintegration(settings)) {
    preint_.texture().bind(unit);
    prog.set("u_preint", unit++);
    prog.set("u_preintSize", static_cast<float>(preint_.entries()));
  } else {
    lut_.texture().bind(unit);
    prog.set("u_tf", unit++);
    prog.set("u_tfSize", static_cast<float>(lutSize_));
  }
  unit += fusion_.bind(prog, unit, volume_, ds);
  if (blockSize_ > 0) {
    blockTexture_.bind(unit);
    prog.set("u_blocks", unit++);
    prog.set("u_blocksPerUnit",
             glm::vec3(glm::dvec3(volume_.dims()) / static_cast<double>(blockSize_)));
    prog.set("u_blockCount", glm::vec3(blocks_.blockCount()));
    prog.set("u_log2MaxMultiplier",
             static_cast<float>(std::log2(std::max(1, settings.sampling.maxMultiplier))));
    if (context_.caps().api == gpu::ApiLevel::Gles2) {
      prog.set("u_blockTilesX", static_cast<float>(blockTilesX_));
      prog.set("u_blockTexSize", glm::vec2(blockTexSize_));
    }
  }

  gpu::apply({});
  triangle_.draw();
  gpu::finish();
  gpu::checkErrors("ray casting");
}

// Makes target_ a width x height target. Previews and full frames alternate
// (the page's store view, the viewer's interactive frames), and a preview's
// size follows its quality controller (16, 17, 18 pixels...): the full
// frame's target and the previews' (each at most a sixteenth of its pixels,
// together at most a sixteenth more memory) are kept and used again, the
// most recent first, since making one costs three waits for a browser's
// GPU process (the errors before and after, the completeness check). Any
// other is let go before a new one is made.
void Raycaster::useTarget(int width, int height) {
  if (target_.id() != 0 && target_.width() == width && target_.height() == height) return;
  const auto pixels = [](const gpu::Framebuffer& f) {
    return static_cast<long long>(f.width()) * f.height();
  };
  gpu::Framebuffer next;
  for (auto it = spareTargets_.begin(); it != spareTargets_.end(); ++it) {
    if (it->width() == width && it->height() == height) {
      next = std::move(*it);
      spareTargets_.erase(it);
      break;
    }
  }
  if (target_.id() != 0) spareTargets_.insert(spareTargets_.begin(), std::move(target_));
  const long long wants = static_cast<long long>(width) * height;
  long long full = wants;
  for (const gpu::Framebuffer& f : spareTargets_) full = std::max(full, pixels(f));
  if (16 * wants > full) full = wants;  // not a preview: larger targets are let go
  bool fullKept = wants == full;
  long long previews = wants < full ? wants : 0;
  std::vector<gpu::Framebuffer> kept;
  for (gpu::Framebuffer& f : spareTargets_) {
    if (!fullKept && pixels(f) == full) {
      fullKept = true;
      kept.push_back(std::move(f));
    } else if (16 * (previews + pixels(f)) <= full) {
      previews += pixels(f);
      kept.push_back(std::move(f));
    }
  }
  spareTargets_ = std::move(kept);  // the rest let go here
  target_ = next.id() != 0 ? std::move(next)
                           : gpu::Framebuffer::create(context_.ledger(), "ray-cast target", width,
                                                      height, gpu::rgba8For(context_.caps().api));
}

Image Raycaster::readImage() const {
  return render::readImage(target_);
}

// ---- The Technique interface and the registry's entry.

void Raycaster::prepare(const Camera&, const RenderSettings& settings) {
  prepare(settings);
}

const gpu::Texture& Raycaster::render(const Camera& camera, const RenderSettings& settings,
                                      int width, int height, double viewAspect) {
  // This frame's rays cover the screen's aspect; the next one's its own again.
  struct RestoreAspect {
    double& aspect;
    double saved;
    ~RestoreAspect() { aspect = saved; }
  } restore{viewAspect_, viewAspect_};
  viewAspect_ = viewAspect;
  renderFrame(camera, settings, width, height);
  return colorTexture();
}

TechniqueReport Raycaster::report() const {
  TechniqueReport r;
  r.occupiedBlockFraction = occupiedFraction_;
  r.gradient = gradient_.plan().reason;
  return r;
}

int Raycaster::skipBlockFor(const gpu::DeviceLimits& limits, int requested) {
  return requested > 0 && limits.textureUnits < kOwnTextureUnits + 1 ? 0 : requested;
}

TechniqueRequirements Raycaster::requirements(const gpu::DeviceLimits& limits,
                                              glm::ivec3 volumeDims,
                                              const TechniqueOptions& options) {
  TechniqueRequirements r;
  const int skipBlock = skipBlockFor(limits, options.skipBlock);
  if (skipBlock != options.skipBlock) {
    r.note = "empty-space skipping off: " + limits.profile + " has " +
             std::to_string(limits.textureUnits) + " texture units";
  }
  r.textureUnits = skipBlock > 0 ? kOwnTextureUnits : 1;
  const std::uint64_t target = static_cast<std::uint64_t>(options.imageSize.x) *
                               static_cast<std::uint64_t>(options.imageSize.y) * 4;
  // The 1D TF table or the pre-integration table (at most 1024^2 RGBA16F),
  // counted at the default size.
  const std::uint64_t lut = std::max<std::uint64_t>(
      4096 * 8, static_cast<std::uint64_t>(PreIntegrationTable::kDefaultEntries) *
                    PreIntegrationTable::kDefaultEntries * 8);
  std::uint64_t blocks = 0;
  if (skipBlock > 0) {
    const glm::u64vec3 c =
        (glm::u64vec3(volumeDims) + glm::u64vec3(skipBlock - 1)) / glm::u64vec3(skipBlock);
    // At most RGBA8 per block (ES 2), plus the slack of the grid mosaic's last row.
    blocks = c.x * c.y * c.z * 4 + c.x * c.y * 4 * 64;
  }
  r.bytes = target + lut + blocks + 4096;  // + vertex buffers
  return r;
}

SamplingTwin Raycaster::samplingTwin(const RenderSettings& settings) const {
  SamplingTwin twin;
  if (stepGrid_.valid() && usesAdaptiveSampling(settings)) twin.steps = &stepGrid_;
  if (precomputedGradient(settings)) twin.gradients = &gradientTexture().gradients();
  twin.preintegrated = usesPreintegration(settings);
  if (twin.preintegrated) {
    twin.preintegrationBuildMs = preint_.lastBuildMs();
    twin.preintegrationUploadMs = preint_.lastUploadMs();
  }
  return twin;
}

TechniqueEntry Raycaster::registration() {
  return {.name = "raycast",
          .summary = "single-pass ray casting",
          .honoursSampling = true,
          .scissorsToVolume = true,
          .drawsChannels = true,
          .drawsChannelBricks = true,
          .requirements = &Raycaster::requirements,
          .create = [](const TechniqueSetup& s) -> std::unique_ptr<Technique> {
            if (!s.layout) throw Error("raycast samples a layout, and none was made");
            auto caster = std::make_unique<Raycaster>(s.context, s.volume, *s.layout);
            caster->setSkipBlockSize(skipBlockFor(s.limits, s.options.skipBlock));
            caster->setLutSize(s.options.lutSize);
            caster->setGradient(layout::parseGradientWish(s.options.gradient));
            return caster;
          }};
}

}  // namespace tessera::render
