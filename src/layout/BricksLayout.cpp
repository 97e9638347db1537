#include "tessera/layout/BricksLayout.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>

#include <glm/trigonometric.hpp>

#include "layout/ChannelUniforms.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/gpu/Draw.h"
#include "tessera/lod/InCoreMultiresSource.h"

namespace tessera::layout {

namespace {

constexpr std::uint64_t kDefaultAtlasCap = 256ull << 20;
constexpr int kCoarsestSide = 16;
// What the process holds besides the atlas, the brick cache and a store's
// decoded chunks while it streams: code, the GL driver, the render target
// and its read-back, bricks in flight in the reader threads and in upload,
// a store's few MiB of stored (compressed) chunk bytes. Measured on
// llvmpipe: head:1024 on shield-k1 (512² image)
// peaked at 468 MiB with a 255 MiB atlas and a 54 MiB cache, so 159 MiB;
// with a margin.
constexpr std::uint64_t kHostOverhead = 176ull << 20;
// The cache never goes below a frame's uploads and the bricks behind them.
constexpr std::uint64_t kMinCacheBytes = 32ull << 20;

// The atlas counts against the host budget as well as the texture budget.
// On llvmpipe the "GPU" is the CPU and the atlas lives in the process. On
// unified-memory mobile GPUs (Tegra K1 in the Shield, the iPad's PowerVR)
// texture memory is the same DRAM as the heap: the driver allocates the
// atlas out of the RAM the OS allows the app (Android's low-memory killer
// and iOS's jetsam count it against the process), and a desktop driver
// often keeps a shadow copy in system memory too. So the host budget pays
// for atlas + brick cache + overhead; the cache gets what the atlas leaves.
// A host budget below the process's own footprint (tests of the planner
// with a few MiB) cannot be honoured this way: the atlas is then not
// weighed against it and the cache takes a quarter of it.
//
// The page table costs the host three times its texture: the host copy the
// CPU rebuilds in place, each cell's stored range (two u16) for the
// empty-space blocks, and the driver's copy (llvmpipe's texture is process
// memory). At 128^3 cells that is 24 MiB.
std::uint64_t pageHostBytes(std::uint64_t pageBytes) {
  return 3 * pageBytes;
}

bool weighsAtlas(const gpu::DeviceLimits& limits, const BricksOptions& options,
                 std::uint64_t pageBytes) {
  return limits.hostBudget > kHostOverhead + kMinCacheBytes + pageHostBytes(pageBytes) &&
         options.cacheBytes == 0;
}

std::uint64_t atlasCap(const gpu::DeviceLimits& limits, const BricksOptions& options,
                       std::uint64_t pageBytes) {
  std::uint64_t avail = options.atlasBytesCap ? options.atlasBytesCap : kDefaultAtlasCap;
  if (limits.textureBudget != 0) {
    avail =
        std::min(avail, limits.textureBudget > pageBytes ? limits.textureBudget - pageBytes : 0);
  }
  if (weighsAtlas(limits, options, pageBytes)) {
    // When the atlas does not fit beside a minimal cache, it shrinks.
    avail = std::min(avail,
                     limits.hostBudget - kHostOverhead - kMinCacheBytes - pageHostBytes(pageBytes));
  }
  return avail;
}

// The sources' decoded chunks take at most an eighth of the host budget
// (the share a store opened alone keeps, ZarrMultiresSource).
constexpr std::uint64_t kChunkCacheShare = 8;

// The host budget shared out (BricksHostSplit): the atlas, the page table
// and the overhead first (atlasCap left at least a minimal brick cache
// beside them), then the sources' decoded chunks (what they would keep, at
// most an eighth of the budget, never eating into the minimal brick
// cache), then the brick cache (the rest, at most a quarter of the budget:
// a roomy host, half of a desktop's RAM, keeps a cache of the usual size).
// Without a host budget: a 64 MiB brick cache, the chunks the sources keep.
BricksHostSplit splitHost(const gpu::DeviceLimits& limits, const BricksOptions& options,
                          std::uint64_t atlasBytes, std::uint64_t pageBytes,
                          std::uint64_t chunksWanted) {
  BricksHostSplit s;
  s.budget = limits.hostBudget;
  const std::uint64_t chunkShare = s.budget ? s.budget / kChunkCacheShare : chunksWanted;
  s.chunkCache = std::min(chunksWanted, chunkShare);
  if (options.cacheBytes != 0) {
    s.brickCache = options.cacheBytes;
  } else if (s.budget == 0) {
    s.brickCache = 64ull << 20;
  } else if (!weighsAtlas(limits, options, pageBytes)) {
    s.brickCache = s.budget / 4;
  } else {
    s.atlas = atlasBytes;
    s.pages = pageBytes;
    // The page table's host copies beyond its texture (pageHostBytes) count
    // as overhead.
    s.overhead = kHostOverhead + (pageHostBytes(pageBytes) - pageBytes);
    const std::uint64_t used = atlasBytes + pageHostBytes(pageBytes) + kHostOverhead;
    const std::uint64_t left = s.budget > used ? s.budget - used : 0;
    s.chunkCache = std::min(s.chunkCache, left > kMinCacheBytes ? left - kMinCacheBytes : 0);
    s.brickCache = std::max(kMinCacheBytes, std::min(left - s.chunkCache, s.budget / 4));
  }
  return s;
}

// "prefix7suffix" (snprintf: GCC 12 -Wrestrict misfires on "literal" + std::string).
std::string numbered(const char* prefix, int n, const char* suffix = "") {
  char text[64];
  std::snprintf(text, sizeof text, "%s%d%s", prefix, n, suffix);
  return text;
}

std::string dimsText(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

// The page table's side at most: the device's 2D limit, or less on request.
int pageTableSide(const gpu::DeviceLimits& limits, const BricksOptions& options) {
  return options.pageTableMaxSide > 0 ? std::min(options.pageTableMaxSide, limits.max2DTextureSize)
                                      : limits.max2DTextureSize;
}

// Level-0 brick cells at most for a brick size chosen here: the page table
// is rebuilt on the CPU at every update (one texel and a range per cell), so
// 128^3 cells (8 MiB of texture, 24 MiB of host: pageHostBytes) is where a
// larger brick is cheaper than a finer cut.
constexpr std::int64_t kMaxChosenCells = std::int64_t(1) << 21;

// The brick of a volume held in host memory (lod::InCoreMultiresSource: a
// file drawn with `--layout bricks`, the in-core half of `tessera bench
// --bricks-vs-incore`). It has no chunk to align to and a read is a copy, so
// the brick size decides neither what is read nor how often; it decides how
// many cells a ray walks (raycast.frag.glsl: each cell a ray enters costs an
// outer iteration, and the SIMD lanes that leave their cell first wait for
// the others) and the apron's share of a slot ((66/64)^3 = 1.10 of the
// brick's voxels, (34/32)^3 = 1.20). On llvmpipe 64^3 instead of 32^3 took
// the bricked frame from 1.24-1.32x to 1.09-1.23x of in-core (CPU time, ch2,
// a 384^3 and a 512^3 u16 phantom; docs/large-data.md, the brick walk).
constexpr int kInCoreBrickSize = 64;

// The page table holds one texel per level-0 brick cell, its z-slices tiled
// in 2D (BricksLayout::pageTableGeometry). For a source without a natural
// chunk, the brick doubles from 32 up to 128 until the table fits the
// device's 2D limit and has at most kMaxChosenCells cells: 4096^3 takes 32^3
// bricks (128^3 cells: 2048 x 1024 texels under ipad2), 8192^3 64^3; see
// docs/large-data.md "Scale".
int brickSizeFor(const BricksOptions& options, glm::ivec3 chunk, glm::ivec3 dims,
                 const gpu::DeviceLimits& limits) {
  if (options.brickSize > 0) return options.brickSize;
  if (chunk.x == chunk.y && chunk.y == chunk.z && chunk.x >= 16 && chunk.x <= 128) return chunk.x;
  int b = 32;
  for (; b < 128; b *= 2) {
    const glm::ivec3 cells = (dims + b - 1) / b;
    const std::int64_t count = std::int64_t(cells.x) * cells.y * cells.z;
    const int side = pageTableSide(limits, options);
    if (count <= kMaxChosenCells && BricksLayout::pageTableGeometry(cells, side).tilesX > 0) break;
  }
  return b;
}

// The atlas the budget allows: its slot grid and, on ES 2, its mosaic.
// ES 2: slots.x is the number of mosaic textures (one unit each, up to 8),
// slots.z the slots stacked in each.
struct AtlasShape {
  glm::ivec3 slots{0};
  MosaicLayout::Geometry mosaic;  // tilesX = 0 on ES 3
  std::uint64_t bytes = 0;
  int count() const { return slots.x * slots.y * slots.z; }
};

constexpr int kMaxMosaicAtlases = 8;

// Channels of a slot: four a texel, in one atlas or two at the same slot.
int channelAtlases(int channels) {
  return (channels + 3) / 4;
}

// How the atlas holds stored values (lod::StoredMapping): u8 in one 8-bit
// channel; 16-bit values in R16 where the context has EXT_texture_norm16,
// else as two 8-bit channels (RG8 on ES 3, LUMINANCE_ALPHA on ES 2), NEAREST,
// that bricks.glsl recombines per texel before it interpolates (GPUs that
// filter 8-bit channels in fixed point round each filtered byte).
struct AtlasFormat {
  gpu::TexelFormat format = gpu::TexelFormat::R8;
  int texel = 0;  // BRICKS_TEXEL in bricks.glsl
  std::uint64_t bytes = 1;
  const char* name = "R8";
  bool twoBytes() const { return texel >= 2; }  // NEAREST, interpolated in the shader
};

// Channels (BricksLayout::createChannels): four a texel, 16 bits each on
// ES 3 (RGBA16 with EXT_texture_norm16, else RGBA16F), 8 on ES 2 (RGBA8, as
// ChannelLayout's mosaic), filtered; `bytes` counts every atlas of a slot.
AtlasFormat channelAtlasFormat(int channels, const gpu::DeviceLimits& limits) {
  const auto atlases = static_cast<std::uint64_t>(channelAtlases(channels));
  if (limits.api != gpu::ApiLevel::Gles3) {
    return {gpu::rgba8For(limits.api), 0, 4 * atlases, "RGBA8 (4 channels a texel)"};
  }
  if (limits.norm16Textures) {
    return {gpu::TexelFormat::RGBA16, 1, 8 * atlases, "RGBA16 (4 channels a texel)"};
  }
  return {gpu::TexelFormat::RGBA16F, 1, 8 * atlases, "RGBA16F (4 channels a texel)"};
}

AtlasFormat atlasFormatFor(ScalarType type, const gpu::DeviceLimits& limits, int channels) {
  if (channels > 0) return channelAtlasFormat(channels, limits);
  const bool es3 = limits.api == gpu::ApiLevel::Gles3;
  if (type == ScalarType::U8) {
    return es3 ? AtlasFormat{gpu::TexelFormat::R8, 0, 1, "R8"}
               : AtlasFormat{gpu::TexelFormat::Luminance8, 0, 1, "L8"};
  }
  if (es3 && limits.norm16Textures) return {gpu::TexelFormat::R16, 1, 2, "R16"};
  if (es3) return {gpu::TexelFormat::RG8, 2, 2, "RG8 (16 bits as two bytes)"};
  return {gpu::TexelFormat::LuminanceAlpha8, 3, 2, "LA8 (16 bits as two bytes)"};
}

// The brick walk's map per cell as floats (bricks.glsl BRICKS_WALK_PAGES,
// an RGBA32F texel per page-table texel): ES 3, a filtered atlas (R8, R16),
// one factor on every axis of every level, the walk on, no channels, and at
// most 64^3 cells (4 MiB). Entering a cell is then one fetch and two
// multiply-adds instead of the RGBA8 decoding and the loop over the levels'
// scales.
bool keepsWalkPages(const gpu::DeviceLimits& limits, const BricksOptions& options,
                    const AtlasFormat& format, bool isotropic, glm::ivec3 cells0) {
  const bool fewCells = std::int64_t(cells0.x) * cells0.y * cells0.z <= (std::int64_t(1) << 18);
  return limits.api == gpu::ApiLevel::Gles3 && format.texel < 2 && isotropic && options.walk &&
         options.channels == 0 && fewCells;
}

PlannedTexture walkPagesTexture(const MosaicLayout::Geometry& pages) {
  return {.label = "brick walk pages",
          .size = {pages.width(), pages.height(), 1},
          .is3D = false,
          .format = "RGBA32F",
          .bytes = 16ull * static_cast<std::uint64_t>(pages.width()) *
                   static_cast<std::uint64_t>(pages.height())};
}

// Whether every level reduces the one before by one factor on all axes,
// from the level dims alone (an axis of one voxel kept at one fits any
// factor): the plan's guess at lod::BrickGrid::scale's isotropy.
bool isotropicLevels(const std::vector<glm::ivec3>& levels) {
  for (std::size_t l = 1; l < levels.size(); ++l) {
    int f = 0;
    for (int a = 0; a < 3; ++a) {
      const int prev = levels[l - 1][a], cur = levels[l][a];
      if (prev == 1 && cur == 1) continue;
      const int fa = cur > 0 ? (prev + cur - 1) / cur : 0;
      if (f != 0 && fa != f) return false;
      f = fa;
    }
  }
  return true;
}

// The page table's bytes and the walk's pages' (every planned texture but
// the atlases).
std::uint64_t tableBytes(const LayoutPlan& plan) {
  std::uint64_t bytes = 0;
  for (const PlannedTexture& t : plan.textures) {
    if (t.label.rfind("brick atlas", 0) != 0) bytes += t.bytes;
  }
  return bytes;
}

// The plan as built: its walk pages as the layout keeps them (the pyramid's
// exact factors decide; planFor guesses them from the dims).
void syncWalkPagesPlan(LayoutPlan& plan, const MosaicLayout::Geometry& pages, bool kept) {
  auto& t = plan.textures;
  const auto it = std::find_if(
      t.begin(), t.end(), [](const PlannedTexture& p) { return p.label == "brick walk pages"; });
  if (it != t.end() && !kept) {
    plan.totalBytes -= it->bytes;
    t.erase(it);
  } else if (it == t.end() && kept) {
    t.push_back(walkPagesTexture(pages));
    plan.totalBytes += t.back().bytes;
  }
}

AtlasShape atlasFor(const gpu::DeviceLimits& limits, int stored, std::uint64_t avail,
                    std::uint64_t bricks, std::uint64_t texelBytes) {
  AtlasShape a;
  const std::uint64_t slotBytes = static_cast<std::uint64_t>(stored) * stored * stored * texelBytes;
  const std::uint64_t want = std::min<std::uint64_t>(avail / slotBytes, bricks);
  if (want == 0) return a;
  if (limits.api == gpu::ApiLevel::Gles3 && limits.max3DTextureSize > 0) {
    const int m = std::min(255, limits.max3DTextureSize / stored);
    if (m < 1) return a;
    const int side = std::clamp(static_cast<int>(std::cbrt(static_cast<double>(want))), 1, m);
    const std::uint64_t layer = static_cast<std::uint64_t>(side) * side;
    // Enough layers for every brick wanted, as far as the budget goes.
    const int depth = static_cast<int>(std::min<std::uint64_t>(
        {static_cast<std::uint64_t>(m), (want + layer - 1) / layer, avail / slotBytes / layer}));
    a.slots = {side, side, std::max(1, depth)};
    a.bytes = slotBytes * static_cast<std::uint64_t>(a.count());
    return a;
  }
  const std::uint64_t tiles = static_cast<std::uint64_t>(limits.max2DTextureSize / stored) *
                              static_cast<std::uint64_t>(limits.max2DTextureSize / stored);
  int depth = static_cast<int>(std::min<std::uint64_t>({255, tiles / stored, want}));
  for (; depth > 0; --depth) {
    a.mosaic = MosaicLayout::geometryFor({stored, stored, depth * stored}, limits.max2DTextureSize);
    a.bytes = static_cast<std::uint64_t>(a.mosaic.width()) * a.mosaic.height() * texelBytes;
    if (a.mosaic.tilesX > 0 && a.bytes <= avail) break;
  }
  if (depth <= 0) return a;
  // More textures where units and budget allow and bricks want them.
  const std::uint64_t perTexture = a.bytes;
  const int units = std::min(kMaxMosaicAtlases, limits.textureUnits - 1);
  const auto textures = static_cast<int>(std::min<std::uint64_t>(
      {static_cast<std::uint64_t>(std::max(1, units)),
       (want + static_cast<std::uint64_t>(depth) - 1) / static_cast<std::uint64_t>(depth),
       std::max<std::uint64_t>(1, avail / perTexture)}));
  a.slots = {textures, 1, depth};
  a.bytes = perTexture * static_cast<std::uint64_t>(textures);
  return a;
}

// How values are kept, for the plan.
std::string storedNote(const Volume& shape) {
  const lod::StoredMapping m = lod::StoredMapping::of(shape);
  if (m.bits == 8) return "";
  if (m.exact) return ", every " + std::string(scalarTypeName(shape.type())) + " value exact";
  char text[96];
  std::snprintf(text, sizeof text, ", 16 bits over the value range (a step of %.3g)",
                m.width / m.maxStored());
  return text;
}

// The limits the atlas is shaped within: with channels, the units one group
// of four channels may take on ES 2 (channelAtlasUnits).
gpu::DeviceLimits shapeLimits(const gpu::DeviceLimits& limits, const BricksOptions& options) {
  gpu::DeviceLimits l = limits;
  if (options.channels > 0) l.textureUnits = channelAtlasUnits(limits, options.channels);
  return l;
}

// How channels are kept (BricksLayout::createChannels), for the plan.
std::string channelNote(gpu::TexelFormat format) {
  if (format == gpu::TexelFormat::RGBA16) return ", 16 bits per channel (u16 and i16 exact)";
  if (format == gpu::TexelFormat::RGBA16F) return ", half floats (11 bits) per channel";
  return ", 8 bits over each channel's value range";
}

std::uint64_t pyramidBricks(const std::vector<glm::ivec3>& levels, int brick) {
  std::uint64_t n = 0;
  for (glm::ivec3 d : levels) {
    const glm::ivec3 b = (d + brick - 1) / brick;
    n += static_cast<std::uint64_t>(b.x) * b.y * b.z;
  }
  return n;
}

}  // namespace

LayoutPlan BricksLayout::planFor(const Volume& shape, const gpu::DeviceLimits& limits,
                                 const BricksOptions& options, glm::ivec3 chunk,
                                 const std::vector<glm::ivec3>& sourceLevels) {
  LayoutPlan plan;
  plan.layout = "bricks";
  const glm::ivec3 d = shape.dims();
  const int b = brickSizeFor(options, chunk, d, limits);
  const int stored = b + 2;
  const std::string vol = dimsText(d) + " " + std::string(scalarTypeName(shape.type()));
  const glm::ivec3 cells = (d + b - 1) / b;
  const std::vector<glm::ivec3> levels =
      sourceLevels.empty() ? lod::pyramidDims(d, kCoarsestSide) : sourceLevels;
  const glm::ivec3 top = (levels.back() + b - 1) / b;
  const int topBricks = top.x * top.y * top.z;
  const int pageSide = pageTableSide(limits, options);
  const MosaicLayout::Geometry pageTiles = pageTableGeometry(cells, pageSide);
  PlannedTexture pages{.label = "brick page table",
                       .size = {pageTiles.width(), pageTiles.height(), 1},
                       .is3D = false,
                       .format = "RGBA8",
                       .bytes = 4ull * static_cast<std::uint64_t>(pageTiles.width()) *
                                static_cast<std::uint64_t>(pageTiles.height())};
  if (pageTiles.tilesX == 0) {
    plan.reason = vol + ": the " + dimsText(cells) + " cells of " + std::to_string(b) +
                  "^3 bricks do not fit a " + std::to_string(pageSide) + "x" +
                  std::to_string(pageSide) + " page table (max 2D texture size of " +
                  limits.profile + ")";
    return plan;
  }
  if (limits.textureUnits < 2) {
    plan.reason = "bricks need two texture units (atlas and page table) on " + limits.profile;
    return plan;
  }
  const AtlasFormat format = atlasFormatFor(shape.type(), limits, options.channels);
  const std::optional<PlannedTexture> walkPages =
      keepsWalkPages(limits, options, format, isotropicLevels(levels), cells)
          ? std::optional<PlannedTexture>(walkPagesTexture(pageTiles))
          : std::nullopt;
  const std::uint64_t pageTableBytes = pages.bytes + (walkPages ? walkPages->bytes : 0);
  const std::uint64_t avail = atlasCap(limits, options, pageTableBytes);
  const AtlasShape a =
      atlasFor(shapeLimits(limits, options), stored, avail, pyramidBricks(levels, b), format.bytes);
  const bool es3 = a.mosaic.tilesX == 0;
  const int atlases = (options.channels > 0 ? channelAtlases(options.channels) : 1) *
                      (es3 ? 1 : std::max(1, a.slots.x));
  PlannedTexture atlas{
      .label = "brick atlas",
      .size = es3 ? a.slots * stored : glm::ivec3(a.mosaic.width(), a.mosaic.height(), 1),
      .is3D = es3,
      .format = format.name,
      .bytes = a.bytes / static_cast<std::uint64_t>(atlases)};
  for (int t = 0; t < atlases; ++t) {
    plan.textures.push_back(atlas);
    if (atlases > 1) plan.textures.back().label += numbered(" ", t + 1);
  }
  plan.textures.push_back(pages);
  if (walkPages) plan.textures.push_back(*walkPages);
  plan.totalBytes = a.bytes + pageTableBytes;
  const std::string what =
      (options.channels > 0 ? numbered("", options.channels, " channels of ") : std::string()) +
      vol + " as " + std::to_string(b) + "^3 bricks (+1 voxel apron) of " +
      std::to_string(levels.size()) + " levels, streamed into a " + std::to_string(a.count()) +
      "-brick " + atlas.format + " atlas (" +
      (atlases > 1 ? numbered("", atlases, " x ") : std::string()) + dimsText(atlas.size) +
      (es3 ? " 3D" : " mosaic") + ", " + formatBytes(a.bytes) + ") through a " +
      std::to_string(pages.size.x) + "x" + std::to_string(pages.size.y) + " page table" +
      (options.channels > 0
           ? channelNote(format.format) + channelSlotsNote(a.slots, es3, options.channels)
           : storedNote(shape));
  // The coarsest bricks are pinned, so refining needs a slot beyond them;
  // a pyramid of one level (a single-level store) needs none: it fits when
  // the atlas holds all of it.
  const bool wholePyramid = static_cast<std::uint64_t>(a.count()) >= pyramidBricks(levels, b);
  if (a.count() <= topBricks && !wholePyramid) {
    plan.reason = what + ": the budget (" + formatBytes(avail) + ") holds no more than the " +
                  std::to_string(topBricks) + " coarsest bricks";
    return plan;
  }
  plan.fits = true;
  plan.reason = what;
  return plan;
}

MosaicLayout::Geometry BricksLayout::pageTableGeometry(glm::ivec3 cells, int maxSide) {
  return MosaicLayout::geometryFor(cells, maxSide);
}

BricksLayout::~BricksLayout() {
  streamer_.reset();  // stop the readers before the textures go
  channelStreamers_.clear();
}

std::unique_ptr<BricksLayout> BricksLayout::create(
    std::shared_ptr<const lod::MultiresSource> source, const gpu::DeviceLimits& limits,
    gpu::MemoryLedger& ledger, const BricksOptions& options) {
  BricksOptions single = options;
  single.channels = 0;
  // Only a pyramid in host memory: a store's or a virtual volume's brick
  // also sets what is read and how finely levels mix (brickSizeFor).
  if (single.brickSize == 0 && source && source->readsFromHostMemory()) {
    single.brickSize = kInCoreBrickSize;
  }
  return build({std::move(source)}, nullptr, limits, ledger, single);
}

std::unique_ptr<BricksLayout> BricksLayout::createChannels(
    std::vector<std::shared_ptr<const lod::MultiresSource>> sources, const ChannelSet& set,
    const gpu::DeviceLimits& limits, gpu::MemoryLedger& ledger, BricksOptions options) {
  if (sources.empty() || static_cast<int>(sources.size()) != set.size()) {
    throw Error("bricks layout: " + std::to_string(sources.size()) + " sources for " +
                std::to_string(set.size()) + " channels");
  }
  for (std::size_t c = 1; c < sources.size(); ++c) {
    for (int lv = 0; lv < sources[0]->levelCount(); ++lv) {
      if (sources[c]->levelCount() != sources[0]->levelCount() ||
          sources[c]->levelInfo(lv).dims != sources[0]->levelInfo(lv).dims) {
        throw InputError("channel " + set[static_cast<int>(c)].label + " (" +
                         sources[c]->describe() + "): its levels differ from channel " +
                         set[0].label + "'s; the channels of one brick must share one grid");
      }
    }
  }
  options.channels = set.size();
  return build(std::move(sources), &set, limits, ledger, options);
}

std::unique_ptr<BricksLayout> BricksLayout::build(
    std::vector<std::shared_ptr<const lod::MultiresSource>> sources, const ChannelSet* set,
    const gpu::DeviceLimits& limits, gpu::MemoryLedger& ledger, const BricksOptions& options) {
  std::shared_ptr<const lod::MultiresSource> source = sources.front();
  if (!source) throw Error("bricks layout: no source");
  std::unique_ptr<BricksLayout> l(new BricksLayout());
  l->channels_ = set;
  l->options_ = options;
  l->walk_ = options.walk;
  l->api_ = limits.api;
  l->source_ = source;
  const glm::ivec3 chunk = source->levelInfo(0).chunk;
  std::vector<glm::ivec3> levels;
  for (int lv = 0; lv < source->levelCount(); ++lv) levels.push_back(source->levelInfo(lv).dims);
  // Each level's own factor per axis (InputError naming the level and axis
  // where a level is no integer reduction of the one before).
  const int b = brickSizeFor(options, chunk, source->shape().dims(), limits);
  l->grid_ = lod::BrickGrid::of(*source, b);
  l->plan_ = planFor(source->shape(), limits, options, chunk, levels);
  if (!l->plan_.fits) throw GpuError("bricks layout: " + l->plan_.reason);
  const int stored = l->grid_.stored();
  const std::uint64_t avail = atlasCap(limits, options, tableBytes(l->plan_));
  std::uint64_t bricks = 0;
  for (int lv = 0; lv < l->grid_.levelCount(); ++lv) bricks += l->grid_.brickCount(lv);
  const AtlasFormat format = atlasFormatFor(source->shape().type(), limits, options.channels);
  l->atlasTexel_ = format.texel;
  l->channelFormat_ = format.format;
  const AtlasShape a = atlasFor(shapeLimits(limits, options), stored, avail, bricks, format.bytes);
  l->slotGrid_ = a.slots;
  l->mosaic_ = a.mosaic;
  if (set) {
    l->createChannelAtlases(ledger, format.format, a.slots, a.mosaic, stored);
  } else if (a.mosaic.tilesX == 0) {
    l->atlasTexels_ = a.slots * stored;
    l->atlases_.push_back(gpu::Texture::create3D(
        ledger, "brick atlas (" + std::string(gpu::texelFormatName(format.format)) + ")",
        format.format, l->atlasTexels_.x, l->atlasTexels_.y, l->atlasTexels_.z));
    if (format.twoBytes()) l->atlases_.back().setFilter(gpu::Filter::Nearest);
  } else {
    l->atlasTexels_ = glm::ivec3(stored, stored, a.slots.z * stored);  // each texture's
    for (int t = 0; t < a.slots.x; ++t) {
      l->atlases_.push_back(
          gpu::Texture::create2D(ledger, numbered("brick atlas ", t + 1, " (mosaic)"),
                                 format.format, a.mosaic.width(), a.mosaic.height()));
      if (format.twoBytes()) l->atlases_.back().setFilter(gpu::Filter::Nearest);
    }
  }
  l->pageGeometry_ = pageTableGeometry(l->grid_.bricks(0), pageTableSide(limits, options));
  const int pagesWide = l->pageGeometry_.width();
  const int pagesTall = l->pageGeometry_.height();
  l->pages_host_.assign(4ull * static_cast<std::size_t>(pagesWide) * pagesTall, 0);
  l->pages_ = gpu::Texture::create2D(ledger, "brick page table", gpu::rgba8For(limits.api),
                                     pagesWide, pagesTall, l->pages_host_.data());
  l->pages_.setFilter(gpu::Filter::Nearest);
  bool isotropic = true;
  for (int lv = 0; lv < l->grid_.levelCount(); ++lv) {
    const glm::ivec3 sc = l->grid_.scale(lv);
    isotropic = isotropic && sc.x == sc.y && sc.y == sc.z;
  }
  if (keepsWalkPages(limits, options, format, isotropic, l->grid_.bricks(0))) {
    l->walkHost_.assign(l->pages_host_.size(), 0.0f);
    l->walkPages_ = gpu::Texture::create2D(ledger, "brick walk pages", gpu::TexelFormat::RGBA32F,
                                           pagesWide, pagesTall, l->walkHost_.data());
    l->walkPages_.setFilter(gpu::Filter::Nearest);
  }
  syncWalkPagesPlan(l->plan_, l->pageGeometry_, !l->walkHost_.empty());
  l->slotKey_.assign(static_cast<std::size_t>(a.count()), -1);
  l->slotUsed_.assign(l->slotKey_.size(), 0);
  l->slotPinned_.assign(l->slotKey_.size(), false);
  l->slotFine_.assign(l->slotKey_.size(), {});

  std::uint64_t chunksWanted = 0;
  for (const auto& s : sources) chunksWanted += s->decodedCacheWanted();
  // The walk's float pages count with the page table (texture and host).
  l->hostSplit_ = splitHost(limits, options, a.bytes, tableBytes(l->plan_), chunksWanted);
  l->streamFrom(sources);
  l->pinCoarsest();
  BricksFrame unused;
  l->rebuildPages(TransferFunction(), unused);
  gpu::checkErrors("bricks layout: allocating the atlas and the coarsest level");
  return l;
}

void BricksLayout::streamFrom(
    const std::vector<std::shared_ptr<const lod::MultiresSource>>& sources) {
  lod::BrickStreamerOptions so;
  so.workers = options_.workers;
  if (inlineReads_ >= 0) so.inlineReadsPerRequest = inlineReads_;
  // One brick cache per channel, the same in all; each source's decoded
  // chunks within an equal part of the chunks' share.
  so.cacheBytes = hostSplit_.brickCache / sources.size();
  for (const auto& s : sources) s->limitDecodedCache(hostSplit_.chunkCache / sources.size());
  source_ = sources.front();
  streamer_ = std::make_unique<lod::BrickStreamer>(source_, grid_, so);
  streamer_->retryFailing(retryFailing_);
  for (std::size_t c = 1; c < sources.size(); ++c) {
    channelStreamers_.push_back(std::make_unique<lod::BrickStreamer>(sources[c], grid_, so));
    channelStreamers_.back()->retryFailing(retryFailing_);
  }
  channelPacking_.clear();
  for (std::size_t c = 0; channels_ && c < sources.size(); ++c) {
    const lod::StoredMapping m = lod::StoredMapping::of(sources[c]->shape());
    glm::dvec2 packing(0.0, m.maxStored());
    const ValueRange r = sources[c]->shape().valueRange();
    if (channelFormat_ != gpu::TexelFormat::RGBA16 && channelFormat_ != gpu::TexelFormat::RGBA16F &&
        r.max > r.min) {
      packing = {m.store(r.min), m.store(r.max)};
    }
    channelPacking_.push_back(packing);
  }
}

// The coarsest level, pinned: what every cell falls back to.
void BricksLayout::pinCoarsest() {
  const int top = grid_.levelCount() - 1;
  const glm::ivec3 n = grid_.bricks(top);
  for (int z = 0; z < n.z; ++z) {
    for (int y = 0; y < n.y; ++y) {
      for (int x = 0; x < n.x; ++x) {
        const lod::BrickKey key{top, {x, y, z}};
        const int slot = slotFor(key.id(), 0);
        if (channels_) {
          uploadChannels(slot, channelBricks(key, true));
        } else {
          upload(slot, *streamer_->readNow(key));
        }
        slotPinned_[static_cast<std::size_t>(slot)] = true;
      }
    }
  }
}

bool BricksLayout::replaceSources(std::vector<std::shared_ptr<const lod::MultiresSource>> sources) {
  if (sources.size() != 1 + channelStreamers_.size()) return false;
  for (const auto& s : sources) {
    if (!s || s->levelCount() != grid_.levelCount()) return false;
    if (s->shape().type() != source_->shape().type()) return false;
    if (lod::StoredMapping::of(s->shape()).bits != streamer_->mapping().bits) return false;
    const lod::BrickGrid g = lod::BrickGrid::of(*s, grid_.brickSize());
    for (int l = 0; l < grid_.levelCount(); ++l) {
      if (g.dims(l) != grid_.dims(l) || g.scale(l) != grid_.scale(l)) return false;
    }
  }
  // An error a caller left pending (a front end's own drawing between
  // frames) is not this call's: only what the uploads below raise is.
  gpu::clearErrors();
  // The readers of the old pyramids stop before their bricks go.
  streamer_.reset();
  channelStreamers_.clear();
  std::fill(slotKey_.begin(), slotKey_.end(), -1);
  std::fill(slotUsed_.begin(), slotUsed_.end(), 0);
  std::fill(slotPinned_.begin(), slotPinned_.end(), false);
  for (auto& f : slotFine_) f.clear();
  slotOf_.clear();
  streamFrom(sources);
  pinCoarsest();
  // As after create(): the page table shows the new coarsest level until
  // the next update() judges bricks by its transfer function.
  classified_ = false;
  BricksFrame unused;
  rebuildPages(TransferFunction(), unused);
  ++contentVersion_;  // the atlas changed even where the page table did not
  ++sourcesReplaced_;
  gpu::checkErrors("bricks layout: streaming other pyramids into the atlas");
  return true;
}

glm::ivec3 BricksLayout::slotOrigin(int slot) const {
  const glm::ivec3 s(slot % slotGrid_.x, (slot / slotGrid_.x) % slotGrid_.y,
                     slot / (slotGrid_.x * slotGrid_.y));
  return s;
}

int BricksLayout::slotFor(std::uint64_t id, std::uint64_t frame) {
  int chosen = -1;
  std::uint64_t oldest = frame;
  for (std::size_t s = 0; s < slotKey_.size(); ++s) {
    if (slotKey_[s] < 0) {
      chosen = static_cast<int>(s);
      break;
    }
    if (!slotPinned_[s] && slotUsed_[s] < oldest) {
      oldest = slotUsed_[s];
      chosen = static_cast<int>(s);
    }
  }
  if (chosen < 0) return -1;
  const auto c = static_cast<std::size_t>(chosen);
  if (slotKey_[c] >= 0) slotOf_.erase(static_cast<std::uint64_t>(slotKey_[c]));
  slotKey_[c] = static_cast<std::int64_t>(id);
  slotUsed_[c] = frame;
  slotOf_[id] = chosen;
  return chosen;
}

void BricksLayout::upload(int slot, const lod::StoredBrick& brick) {
  const int n = grid_.stored();
  const glm::ivec3 s = slotOrigin(slot);
  keepFineRanges(slot, brick);
  if (mosaic_.tilesX == 0) {
    atlases_[0].updateRegion(s * n, glm::ivec3(n), brick.bytes.data());
    return;
  }
  // ES 2: s.x is the texture, s.z the slot in its stack of z-slices.
  gpu::Texture& atlas = atlases_[static_cast<std::size_t>(s.x)];
  const std::size_t slice = static_cast<std::size_t>(n) * n * (brick.bits == 8 ? 1 : 2);
  for (int k = 0; k < n; ++k) {
    const glm::ivec2 at = mosaic_.addressOf(0, 0, s.z * n + k);
    atlas.updateRegion({at, 0}, {n, n, 1}, brick.bytes.data() + slice * k);
  }
}

// A level-0 brick's ranges per kFineBlock^3 block, each with the one-voxel
// support its samples reach (the apron holds it): what an in-core layout's
// ValueBlocks hold for the same voxels, so that empty-space skipping and
// adaptive steps decide as they do in core.
void BricksLayout::keepFineRanges(int slot, const lod::StoredBrick& brick) {
  std::vector<std::uint16_t>& fine = slotFine_[static_cast<std::size_t>(slot)];
  fine.clear();
  const int b = grid_.brickSize();
  const auto id = static_cast<std::uint64_t>(slotKey_[static_cast<std::size_t>(slot)]);
  if ((id >> 60) != 0 || b % kFineBlock != 0) return;
  const int per = b / kFineBlock, n = grid_.stored();
  fine.resize(2ull * per * per * per);
  std::size_t i = 0;
  for (int z = 0; z < per; ++z) {
    for (int y = 0; y < per; ++y) {
      for (int x = 0; x < per; ++x, i += 2) {
        // Stored voxel k is brick voxel k - 1: block voxels [xS - 1, xS + S].
        std::uint16_t lo = 65535, hi = 0;
        for (int k = z * kFineBlock; k <= (z + 1) * kFineBlock + 1; ++k) {
          for (int j = y * kFineBlock; j <= (y + 1) * kFineBlock + 1; ++j) {
            const std::size_t row = (static_cast<std::size_t>(k) * n + j) * n;
            for (int h = x * kFineBlock; h <= (x + 1) * kFineBlock + 1; ++h) {
              const std::uint16_t v = brick.value(row + static_cast<std::size_t>(h));
              lo = std::min(lo, v);
              hi = std::max(hi, v);
            }
          }
        }
        fine[i] = lo;
        fine[i + 1] = hi;
      }
    }
  }
}

std::uint64_t BricksLayout::textureBytes() const {
  std::uint64_t bytes = pages_.bytes() + (walkHost_.empty() ? 0 : walkPages_.bytes());
  for (const gpu::Texture& t : atlases_) bytes += t.bytes();
  return bytes;
}

ValueMapping BricksLayout::rawFromStored() const {
  const lod::StoredMapping& m = streamer_->mapping();
  return {m.width, m.min};
}

std::optional<lod::BrickRange> BricksLayout::subtreeBound(
    const lod::BrickKey& key, const lod::BrickStreamer& streamer) const {
  // The nearest range read (the brick's own or an ancestor's, with its
  // apron), widened down to level 0. Only a mean pyramid of identity-stored
  // values bounds finer levels; otherwise nothing is known of the bricks
  // under a read one until they are read themselves (a small bright finding
  // averaged into a dim coarse brick must not vanish).
  const lod::StoredMapping& m = streamer.mapping();
  const bool mean = source_->meanPyramid() && m.exact;
  for (lod::BrickKey k = key; k.level < grid_.levelCount(); k = grid_.parent(k)) {
    if (auto r = streamer.range(k)) {
      if (k.level == 0) return r;
      if (!mean) return std::nullopt;
      std::vector<int> fanIns;  // from k's level down to level 1
      for (int l = k.level; l >= 1; --l) fanIns.push_back(grid_.fanIn(l));
      return lod::meanPyramidBound(*r, fanIns, m.maxStored());
    }
  }
  return std::nullopt;
}

bool BricksLayout::transparent(const lod::BrickKey& key, const TransferFunction& tf, bool exactOnly,
                               std::uint16_t* value) const {
  if (!classified_) return false;
  if (channels_) return value == nullptr && channelsTransparent(key, tf, exactOnly);
  const std::optional<lod::BrickRange> r =
      exactOnly ? streamer_->range(key) : subtreeBound(key, *streamer_);
  if (!r) return false;
  // The TF's input over the brick's values, as the shader computes it:
  // n = clamp((raw - window min) / window width, 0, 1). The TF is piecewise
  // linear, so it is transparent over [a, b] when it is at both ends and no
  // control point inside is opaque.
  const lod::StoredMapping& m = streamer_->mapping();
  const ValueRange w = source_->shape().window();
  const double ww = w.max > w.min ? w.max - w.min : 1.0;
  const double a = std::clamp((m.raw(r->min) - w.min) / ww, 0.0, 1.0);
  const double b = std::clamp((m.raw(r->max) - w.min) / ww, 0.0, 1.0);
  bool any = tf.opacity(a) > 0.0 || tf.opacity(b) > 0.0;
  for (const OpacityPoint& p : tf.opacities) any = any || (p.alpha > 0.0 && p.x > a && p.x < b);
  if (value) *value = r->min;
  return !any;
}

void BricksLayout::rebuildPages(const TransferFunction& tf, BricksFrame& frame) {
  // Each cell shows the finest of its ancestors (itself included) that is
  // resident or that its own range makes transparent. Resolved top-down, one
  // level at a time, a brick inheriting its parent's page where it is
  // neither: one lookup per brick of the pyramid (about 8/7 of the cells),
  // not one per cell and level.
  const glm::ivec3 cells = grid_.bricks(0);
  const int levels = grid_.levelCount();
  const std::uint16_t maxStored = static_cast<std::uint16_t>(streamer_->mapping().maxStored());
  struct Resolved {
    std::array<std::uint8_t, 4> page{};
    std::uint16_t min = 0, max = 0;
    int level = 0;  // levels: transparent
  };
  auto resolve = [&](const lod::BrickKey& key, const Resolved* parent) {
    Resolved r;
    const auto it = slotOf_.find(key.id());
    if (it != slotOf_.end()) {
      const glm::ivec3 s = slotOrigin(it->second);
      r.page = {static_cast<std::uint8_t>(s.x), static_cast<std::uint8_t>(s.y),
                static_cast<std::uint8_t>(s.z), static_cast<std::uint8_t>(key.level)};
      r.level = key.level;
      r.max = maxStored;
      if (auto range = streamer_->range(key)) {
        r.min = range->min;
        r.max = range->max;
      }
      return r;
    }
    std::uint16_t v = 0;
    if (transparent(key, tf, true, &v)) {
      // The constant value, low byte first.
      r.page = {static_cast<std::uint8_t>(v & 0xff), static_cast<std::uint8_t>(v >> 8), 0, 255};
      r.min = r.max = v;
      r.level = levels;
      return r;
    }
    if (parent) {
      return *parent;
    }
    r.max = maxStored;  // nothing resident (never: the coarsest level is pinned)
    r.page[3] = static_cast<std::uint8_t>(key.level);
    r.level = key.level;
    return r;
  };
  auto indexIn = [&](int level, glm::ivec3 b) {
    const glm::ivec3 n = grid_.bricks(level);
    return (static_cast<std::size_t>(b.z) * n.y + b.y) * n.x + static_cast<std::size_t>(b.x);
  };
  std::vector<Resolved> above;
  for (int l = levels - 1; l >= 1; --l) {
    const glm::ivec3 n = grid_.bricks(l);
    std::vector<Resolved> here(static_cast<std::size_t>(n.x) * n.y * n.z);
    std::size_t i = 0;
    for (int z = 0; z < n.z; ++z) {
      for (int y = 0; y < n.y; ++y) {
        for (int x = 0; x < n.x; ++x, ++i) {
          const lod::BrickKey key{l, {x, y, z}};
          const Resolved* parent =
              l + 1 < levels ? &above[indexIn(l + 1, grid_.parent(key).brick)] : nullptr;
          here[i] = resolve(key, parent);
        }
      }
    }
    above = std::move(here);
  }
  // Rewritten in place (no second copy of the table): only a change is
  // uploaded.
  bool changed = false;
  const std::size_t cellCount = static_cast<std::size_t>(cells.x) * cells.y * cells.z;
  cellMin_.assign(cellCount, 0);
  cellMax_.assign(cellCount, maxStored);
  const std::size_t pagesWide = static_cast<std::size_t>(pageGeometry_.width());
  frame.cellsPerLevel.assign(static_cast<std::size_t>(levels) + 1, 0);
  std::size_t i = 0;
  for (int z = 0; z < cells.z; ++z) {
    for (int y = 0; y < cells.y; ++y) {
      const glm::ivec2 rowStart = pageGeometry_.addressOf(0, y, z);
      std::uint8_t* row = &pages_host_[4 * (static_cast<std::size_t>(rowStart.y) * pagesWide +
                                            static_cast<std::size_t>(rowStart.x))];
      for (int x = 0; x < cells.x; ++x, ++i) {
        const lod::BrickKey key{0, {x, y, z}};
        const Resolved* parent = levels > 1 ? &above[indexIn(1, grid_.parent(key).brick)] : nullptr;
        const Resolved r = resolve(key, parent);
        std::uint8_t* e = row + 4 * x;
        changed = changed || !std::equal(r.page.begin(), r.page.end(), e);
        std::copy(r.page.begin(), r.page.end(), e);
        cellMin_[i] = r.min;
        cellMax_[i] = r.max;
        if (!walkHost_.empty()) {
          float* w = &walkHost_[static_cast<std::size_t>(e - pages_host_.data())];
          if (r.page[3] == 255) {
            w[0] = static_cast<float>(r.page[0] | (r.page[1] << 8)) / static_cast<float>(maxStored);
            w[1] = w[2] = w[3] = 0.0f;
          } else {
            const int lv = r.page[3];
            const int sl = grid_.scale(lv).x;
            const float b = static_cast<float>(grid_.brickSize());
            const glm::vec3 slot(r.page[0], r.page[1], r.page[2]);
            const glm::vec3 brick(glm::ivec3(x, y, z) / sl);
            const glm::vec3 off = (slot * (b + 2.0f) + 1.0f - brick * b) / glm::vec3(atlasTexels_);
            w[0] = off.x;
            w[1] = off.y;
            w[2] = off.z;
            w[3] = 1.0f / static_cast<float>(sl);
          }
        }
        ++frame.cellsPerLevel[static_cast<std::size_t>(r.level)];
      }
    }
  }
  if (changed) {
    pages_.update(pages_host_.data());
    if (!walkHost_.empty()) walkPages_.update(walkHost_.data());
    ++contentVersion_;
  }
}

BricksFrame BricksLayout::update(const Camera& camera, int width, int height,
                                 const TransferFunction& tf) {
  ++frame_;
  BricksFrame frame;
  classified_ = true;  // transparent() judges bricks by `tf` from now on

  lod::LodView view;
  const glm::dvec3 spacing = source_->shape().spacing();
  const glm::dvec3 dims0(grid_.dims(0));
  view.eye = camera.eye() / spacing + 0.5 * dims0;
  view.spacing = spacing;
  view.orthographic = camera.projection == Projection::Orthographic;
  view.pixelSize = view.orthographic ? 2.0 * camera.orthoHalfHeight() / height
                                     : 2.0 * std::tan(glm::radians(camera.fovYDeg) / 2.0) / height;
  view.pixelsPerVoxel = options_.pixelsPerVoxel;
  (void)width;
  const int pinned = static_cast<int>(std::count(slotPinned_.begin(), slotPinned_.end(), true));
  const std::size_t capacity = static_cast<std::size_t>(slotCount() - pinned);
  // An eighth of the slots stay for the parents of bricks still missing
  // (coarse to fine: a missing brick shows its parent, not a distant ancestor).
  const lod::LodSelection sel = lod::selectBricks(
      grid_, view, [&](const lod::BrickKey& k) { return !transparent(k, tf, false, nullptr); },
      capacity - capacity / 8);
  frame.wanted = static_cast<int>(sel.bricks.size());
  frame.wantedPerLevel = sel.bricksPerLevel;
  frame.limitedByBudget = sel.limitedByCapacity;
  // What to fetch, nearest first and each missing brick after its missing
  // ancestors (coarse to fine); what is on screen now stays (marked used).
  std::vector<lod::BrickKey> needed;
  std::unordered_map<std::uint64_t, bool> inCut;  // id -> part of the cut (not an ancestor)
  auto markUsed = [&](const lod::BrickKey& k) {
    const auto it = slotOf_.find(k.id());
    if (it == slotOf_.end()) return false;
    slotUsed_[static_cast<std::size_t>(it->second)] = frame_;
    return true;
  };
  for (const lod::BrickKey& k : sel.bricks) {
    if (markUsed(k)) continue;
    std::vector<lod::BrickKey> chain;
    for (lod::BrickKey a = grid_.parent(k); a.level < grid_.levelCount(); a = grid_.parent(a)) {
      if (markUsed(a)) break;
      chain.push_back(a);
    }
    for (auto a = chain.rbegin(); a != chain.rend(); ++a) {
      if (inCut.emplace(a->id(), false).second) needed.push_back(*a);
    }
    const auto [it, added] = inCut.emplace(k.id(), true);
    it->second = true;
    if (added) needed.push_back(k);
  }
  std::vector<lod::BrickKey> toRead;
  std::uint64_t bytes = 0;
  const auto t0 = std::chrono::steady_clock::now();
  bool budgetLeft = true;
  for (const lod::BrickKey& k : needed) {
    const bool cut = inCut[k.id()];
    if (slotOf_.count(k.id())) continue;
    // Read since the selection above (a reader thread finished meanwhile)
    // and transparent by its own range: its cells draw the constant, as
    // they would had the read come first, so what is drawn does not depend
    // on which reader thread finishes first.
    if (cut && transparent(k, tf, true, nullptr)) continue;
    if (cut) ++frame.missing;
    std::shared_ptr<const lod::StoredBrick> brick = streamer_->find(k);
    std::vector<std::shared_ptr<const lod::StoredBrick>> bricks;
    if (channels_) {
      bricks = channelBricks(k, false);
      if (bricks.empty()) brick.reset();
    }
    if (!brick) {
      if (cut && streamer_->failing(k)) ++frame.failing;
      toRead.push_back(k);
      continue;
    }
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (bytes >= options_.uploadBytesPerFrame || ms >= options_.uploadMsPerFrame) {
      budgetLeft = false;
    }
    if (!budgetLeft) continue;
    const int slot = slotFor(k.id(), frame_);
    if (slot < 0) continue;  // every slot holds a brick this frame wants
    if (channels_) {
      uploadChannels(slot, bricks);
    } else {
      upload(slot, *brick);
    }
    bytes += brick->bytes.size() * (bricks.empty() ? 1 : bricks.size());
    ++frame.uploaded;
    if (cut) --frame.missing;
  }
  streamer_->request(toRead);
  for (auto& s : channelStreamers_) s->request(toRead);
  rebuildPages(tf, frame);
  frame.complete = frame.missing == frame.failing;
  return frame;
}

void BricksLayout::waitForBricks(double ms) {
  streamer_->waitForProgress(ms);
}

std::vector<int> BricksLayout::cellLevels() const {
  // Cell by cell (x fastest): the table's texels are its z-slices tiled in
  // 2D (pageGeometry_), not the cells in order.
  const glm::ivec3 cells = grid_.bricks(0);
  std::vector<int> out;
  out.reserve(static_cast<std::size_t>(cells.x) * cells.y * static_cast<std::size_t>(cells.z));
  for (int z = 0; z < cells.z; ++z) {
    for (int y = 0; y < cells.y; ++y) {
      for (int x = 0; x < cells.x; ++x) {
        const glm::ivec2 t = pageGeometry_.addressOf(x, y, z);
        const std::uint8_t a =
            pages_host_[4 * (static_cast<std::size_t>(t.y) * pageGeometry_.width() +
                             static_cast<std::size_t>(t.x)) +
                        3];
        out.push_back(a == 255 ? -1 : a);
      }
    }
  }
  return out;
}

BricksLayout::Lookup BricksLayout::lookup(glm::dvec3 x0) const {
  const double b = grid_.brickSize();
  const glm::dvec3 dims0(grid_.dims(0));
  const glm::dvec3 cellsF(grid_.bricks(0));
  x0 = glm::clamp(x0, glm::dvec3(0.0), dims0);
  const glm::dvec3 cell = glm::min(glm::floor(x0 / b), cellsF - 1.0);
  const glm::ivec3 c(cell);
  const glm::ivec2 texel = pageGeometry_.addressOf(c.x, c.y, c.z);
  const std::size_t i =
      static_cast<std::size_t>(texel.y) * pageGeometry_.width() + static_cast<std::size_t>(texel.x);
  const std::uint8_t* e = &pages_host_[4 * i];
  Lookup out;
  if (e[3] == 255) {
    out.level = -1;
    out.texel = glm::dvec3(e[0] | (e[1] << 8), 0.0, 0.0);
    return out;
  }
  out.level = e[3];
  const glm::dvec3 shrink = 1.0 / glm::dvec3(grid_.scale(out.level));
  const glm::dvec3 brick = glm::floor(cell * shrink + 0.001);
  const glm::dvec3 local = glm::clamp(x0 * shrink - brick * b, 0.0, b) + 1.0;
  const bool es3 = mosaic_.tilesX == 0;
  out.texture = es3 ? 0 : e[0];
  out.texel = (es3 ? glm::dvec3(e[0], e[1], e[2]) : glm::dvec3(0.0, 0.0, e[2])) * (b + 2.0) + local;
  return out;
}

ValueBlocks BricksLayout::valueBlocks(int blockSize) const {
  const glm::ivec3 d = grid_.dims(0);
  const glm::ivec3 count = (d + blockSize - 1) / blockSize;
  const glm::ivec3 cells = grid_.bricks(0);
  const int b = grid_.brickSize();
  const lod::StoredMapping& m = streamer_->mapping();
  const std::size_t n = static_cast<std::size_t>(count.x) * count.y * count.z;
  std::vector<float> mins(n), maxs(n);
  std::size_t i = 0;
  for (int z = 0; z < count.z; ++z) {
    for (int y = 0; y < count.y; ++y) {
      for (int x = 0; x < count.x; ++x, ++i) {
        const glm::ivec3 block(x, y, z);
        if (blockSize == kFineBlock && b % kFineBlock == 0) {
          // A block inside one level-0 brick: its own range, as in core.
          const glm::ivec3 cell = block * kFineBlock / b;
          const auto found = slotOf_.find(lod::BrickKey{0, cell}.id());
          const int slot = found == slotOf_.end() ? -1 : found->second;
          if (slot >= 0 && !slotFine_[static_cast<std::size_t>(slot)].empty()) {
            const int per = b / kFineBlock;
            const glm::ivec3 f = block - cell * per;
            const std::size_t at = 2 * ((static_cast<std::size_t>(f.z) * per + f.y) * per +
                                        static_cast<std::size_t>(f.x));
            const std::vector<std::uint16_t>& fine = slotFine_[static_cast<std::size_t>(slot)];
            mins[i] = static_cast<float>(m.raw(fine[at]));
            maxs[i] = static_cast<float>(m.raw(fine[at + 1]));
            continue;
          }
        }
        // Samples inside the block read the cells its box [bS, (b+1)S] touches;
        // a block inside one cell (b a multiple of S), only that cell's page:
        // a transparent cell's constant, a coarser brick's range.
        const glm::ivec3 lo = block * blockSize / b;
        const glm::ivec3 hi =
            b % blockSize == 0 ? lo : glm::min(glm::min((block + 1) * blockSize, d) / b, cells - 1);
        int mn = m.maxStored(), mx = 0;
        for (int cz = lo.z; cz <= hi.z; ++cz) {
          for (int cy = lo.y; cy <= hi.y; ++cy) {
            for (int cx = lo.x; cx <= hi.x; ++cx) {
              const std::size_t c = (static_cast<std::size_t>(cz) * cells.y + cy) * cells.x + cx;
              mn = std::min<int>(mn, cellMin_[c]);
              mx = std::max<int>(mx, cellMax_[c]);
            }
          }
        }
        mins[i] = static_cast<float>(m.raw(mn));
        maxs[i] = static_cast<float>(m.raw(mx));
      }
    }
  }
  return ValueBlocks(count, blockSize, supportVoxels(), std::move(mins), std::move(maxs));
}

std::vector<gpu::ShaderPart> BricksLayout::glslParts() const {
  if (!channels_) return {glsl()};
  return {glsl(), channelsGlsl(), gpu::embeddedShaderPart("layout/channels.glsl")};
}

gpu::ShaderPart BricksLayout::glsl() const {
  gpu::ShaderPart part = gpu::embeddedShaderPart("layout/bricks.glsl");
  // The number of ES 2 atlas samplers, the atlas' texel format and the
  // number of levels (the size of a uniform array) must be compile-time
  // constants; they replace the file's first three lines, comments, so line
  // numbers stay.
  const std::size_t second = part.text.find('\n') + 1;
  const std::size_t third = part.text.find('\n', second) + 1;
  const std::size_t fourth = part.text.find('\n', third) + 1;
  part.text.replace(
      0, part.text.find('\n', fourth),
      "#define BRICKS_ATLASES " +
          std::to_string(channels_ ? channelMosaics() : static_cast<int>(atlases_.size())) +
          "\n#define BRICKS_TEXEL " + std::to_string(atlasTexel_) + "\n#define BRICKS_LEVELS " +
          std::to_string(grid_.levelCount()) + "\n#define BRICKS_WALK_PAGES " +
          (walkHost_.empty() ? "0" : "1"));
  return part;
}

int BricksLayout::bind(const gpu::Program& program, int firstUnit) const {
  pages_.bind(firstUnit);
  program.set("u_layoutPages", firstUnit);
  if (channels_) bindChannels(program, firstUnit + 1);
  for (std::size_t t = 0; t < (channels_ ? 0 : atlases_.size()); ++t) {
    const int unit = firstUnit + 1 + static_cast<int>(t);
    atlases_[t].bind(unit);
    const std::string name = mosaic_.tilesX == 0 ? std::string("u_layoutAtlas")
                                                 : numbered("u_layoutAtlas", static_cast<int>(t));
    program.set(name.c_str(), unit);
  }
  const glm::ivec3 cells = grid_.bricks(0);
  program.set("u_layoutDims0", glm::vec3(grid_.dims(0)));
  program.set("u_layoutBrick", static_cast<float>(grid_.brickSize()));
  program.set("u_layoutCells", glm::vec3(cells));
  program.set("u_layoutPagesInv", glm::vec2(1.0f / static_cast<float>(pageGeometry_.width()),
                                            1.0f / static_cast<float>(pageGeometry_.height())));
  program.set("u_layoutPageTiles", static_cast<float>(pageGeometry_.tilesX));
  if (!walkHost_.empty()) {
    const int unit = firstUnit + 1 + static_cast<int>(atlases_.size());
    walkPages_.bind(unit);
    program.set("u_layoutWalkPages", unit);
    program.set("u_layoutWalkScale0", glm::vec3(grid_.dims(0)) / glm::vec3(atlasTexels_));
  }
  program.set("u_layoutAtlasTexels", glm::vec3(atlasTexels_));
  for (int l = 0; l < grid_.levelCount(); ++l) {
    const std::string name = numbered("u_layoutLevelShrink[", l, "]");
    program.set(name.c_str(), 1.0f / glm::vec3(grid_.scale(l)));
  }
  if (mosaic_.tilesX > 0) {
    program.set("u_layoutTilesX", static_cast<float>(mosaic_.tilesX));
    program.set("u_layoutMosaicInv", glm::vec2(1.0f / static_cast<float>(mosaic_.width()),
                                               1.0f / static_cast<float>(mosaic_.height())));
  }
  return textureUnits();
}

LayoutEntry BricksLayout::registration() {
  return {.name = "bricks",
          .streamsBricks = true,
          .holdsVoxelGrid = false,
          .plan =
              [](const Volume& shape, const gpu::DeviceLimits& limits, int units) {
                gpu::DeviceLimits l = limits;
                l.textureUnits = units;
                return planFor(shape, l);
              },
          .create = [](const Volume& volume, const gpu::DeviceLimits& limits,
                       gpu::MemoryLedger& ledger, int) -> std::unique_ptr<Layout> {
            // The caller keeps `volume` alive for as long as the layout.
            std::shared_ptr<const Volume> borrowed(&volume, [](const Volume*) {});
            return create(std::make_shared<lod::InCoreMultiresSource>(borrowed), limits, ledger);
          },
          .stream = [](std::shared_ptr<const lod::MultiresSource> source,
                       const gpu::DeviceLimits& limits,
                       gpu::MemoryLedger& ledger) -> std::unique_ptr<Layout> {
            return create(std::move(source), limits, ledger);
          }};
}

}  // namespace tessera::layout
