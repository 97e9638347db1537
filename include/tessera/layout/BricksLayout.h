#pragma once
// The volume as bricks of a multiresolution pyramid streamed into a fixed
// atlas behind a page table (Schultz 2016 §7.1.2, §7.3; DESIGN.md "Large
// data"): for volumes that do not fit the device in core. The atlas is a 3D
// texture on ES 3 and a mosaic of its z-slices (MosaicLayout's addressing)
// on ES 2; the page table maps each level-0 brick cell to the finest resident
// brick over it, so missing bricks show their coarser level instead of
// holes (bricks.glsl). Every technique renders it through sampleVolume().
//
// Each frame the caller (the render loop) calls update() with the view: the
// layout picks the level per brick (lod::selectBricks, about one voxel per
// pixel, coarser when the atlas cannot hold the working set), requests the
// missing bricks nearest first from a lod::BrickStreamer (worker threads, an
// LRU host cache within the host budget), uploads at most a byte and time
// budget of bricks into free or least recently used atlas slots, and rewrites
// the page table. Bricks whose exact (or, before they are read, their
// parent's) value range the TF makes transparent are neither fetched nor
// uploaded. The atlas is allocated once, within the texture budget: the
// ledger never grows after create().
//
// Values keep the data's precision (lod::StoredMapping): u8 in 8 bits, u16
// and i16 exactly in 16 bits, f32 in 16 bits over its value range; the
// window is applied in the shader as for in-core layouts, so any window,
// however narrow, gives the in-core image. 16-bit values live in R16 where
// the context has EXT_texture_norm16, else in two 8-bit channels (RG8 on
// ES 3, LUMINANCE_ALPHA on ES 2) recombined in bricks.glsl.
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <unordered_map>
#include <vector>

#include "tessera/core/Camera.h"
#include "tessera/core/ChannelSet.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/MemoryLedger.h"
#include "tessera/layout/Layout.h"
#include "tessera/layout/LayoutRegistry.h"
#include "tessera/layout/MosaicLayout.h"
#include "tessera/layout/StreamingLayout.h"
#include "tessera/lod/BrickStreamer.h"
#include "tessera/lod/LevelSelection.h"

namespace tessera::layout {

struct BricksOptions {
  // B; 0: the source's chunk if cubic 16..128, else 64 for a pyramid in host
  // memory (create: lod::InCoreMultiresSource), else 32 (doubled while the
  // page table does not fit)
  int brickSize = 0;
  // 0: min(texture budget, 256 MiB, host budget - overhead - a minimal cache)
  std::uint64_t atlasBytesCap = 0;
  // Host cache; 0: the host budget less the atlas and a fixed overhead, at
  // most a quarter of it (64 MiB without a host budget). Set, the atlas is
  // not weighed against the host.
  std::uint64_t cacheBytes = 0;
  std::uint64_t uploadBytesPerFrame = 16ull << 20;
  double uploadMsPerFrame = 40.0;  // stop uploading after this long in a frame
  double pixelsPerVoxel = 1.0;     // refine while a voxel covers more pixels
  int workers = 2;                 // reader threads
  // The ray caster walks the bricks (one page read per brick cell a ray
  // enters); false: a page read per sample (tests compare the two).
  bool walk = true;
  // > 0: the channels of createChannels() (planFor weighs their atlases).
  int channels = 0;
  // The page table's side at most; 0: the device's 2D limit (tests force a
  // table of several tile rows with a small one).
  int pageTableMaxSide = 0;
};

// How the device profile's host budget is shared while a volume streams:
// the atlas and page table (weighed against the host: see BricksLayout.cpp),
// a fixed overhead (code, driver, render target, bricks in flight, stored
// chunk bytes), the cache of read bricks and the sources' decoded chunks
// (MultiresSource::limitDecodedCache). With a budget that can be honoured,
// total() <= budget; atlas, pages and overhead are 0 when the budget is
// too small to weigh them (the caches then take a quarter and an eighth of
// it) or there is none (budget 0).
struct BricksHostSplit {
  std::uint64_t budget = 0;
  std::uint64_t atlas = 0;
  std::uint64_t pages = 0;
  std::uint64_t overhead = 0;
  std::uint64_t brickCache = 0;  // all channels together
  std::uint64_t chunkCache = 0;  // all sources together
  std::uint64_t total() const { return atlas + pages + overhead + brickCache + chunkCache; }
};

class BricksLayout final : public Layout, public StreamingLayout {
 public:
  // The atlas and page table for a volume of `shape` within `limits`.
  // `levels`: the source's level dims (empty: a factor-2 pyramid down to 16).
  static LayoutPlan planFor(const Volume& shape, const gpu::DeviceLimits& limits,
                            const BricksOptions& options = {}, glm::ivec3 chunk = glm::ivec3(0),
                            const std::vector<glm::ivec3>& levels = {});
  // Where the page table keeps level-0 brick cell c: its z-slices as tiles of
  // cells.x x cells.y texels side by side within maxSide x maxSide
  // (MosaicLayout::Geometry: addressOf(c.x, c.y, c.z) is c's texel, as in
  // bricks.glsl's pageTexel); tilesX 0 when the cells do not fit.
  static MosaicLayout::Geometry pageTableGeometry(glm::ivec3 cells, int maxSide);

  // Plans, allocates, and reads and uploads the coarsest level (pinned, so
  // there is always something to fall back to). Throws GpuError if the plan
  // does not fit, Error if the coarsest level cannot be read.
  static std::unique_ptr<BricksLayout> create(std::shared_ptr<const lod::MultiresSource> source,
                                              const gpu::DeviceLimits& limits,
                                              gpu::MemoryLedger& ledger,
                                              const BricksOptions& options = {});
  // Several channels of one grid (docs/channels.md "bricks"): one source
  // per channel of `set` (the same level dims), one page table and one slot
  // per brick holding all its channels, four per RGBA texel (RGBA16 3D on
  // ES 3 with EXT_texture_norm16, RGBA16F without, RGBA8 mosaic on ES 2);
  // channels 4-5 in a second atlas at the same slot. A brick is uploaded
  // once every channel of it has been read. Windows, colours, visibility and
  // mode are read from `set` (which must outlive the layout) at update() and
  // bind(). InputError when the sources' grids differ.
  static std::unique_ptr<BricksLayout> createChannels(
      std::vector<std::shared_ptr<const lod::MultiresSource>> sources, const ChannelSet& set,
      const gpu::DeviceLimits& limits, gpu::MemoryLedger& ledger, BricksOptions options = {});
  ~BricksLayout() override;

  // One frame's level selection, requests, uploads and page table. The
  // camera must be framed on shape() (Camera::frame).
  BricksFrame update(const Camera& camera, int width, int height,
                     const TransferFunction& tf) override;
  // Waits (up to ms) for a brick read to finish: the render loop's idle.
  void waitForBricks(double ms) override;
  StreamingLayout* streaming() override { return this; }
  const StreamingLayout* streaming() const override { return this; }

  std::string name() const override { return "bricks"; }
  const LayoutPlan& plan() const override { return plan_; }
  gpu::ShaderPart glsl() const override;
  // glsl(), and for channels layout/channels_bricks.glsl and channels.glsl.
  std::vector<gpu::ShaderPart> glslParts() const override;
  int bind(const gpu::Program& program, int firstUnit) const override;
  ValueMapping rawFromStored() const override;
  glm::ivec3 volumeDims() const override { return grid_.dims(0); }
  std::uint64_t textureBytes() const override;
  // Channels: the page table and the channel atlases (channelUnits()).
  int textureUnits() const override {
    return 1 + (channels_ ? channelUnits() : static_cast<int>(atlases_.size())) +
           (walkHost_.empty() ? 0 : 1);
  }
  ValueBlocks valueBlocks(int blockSize) const override;
  std::uint64_t contentVersion() const override { return contentVersion_; }
  bool walksBricks() const override { return walk_; }
  // Made by createChannels: its seam defines CHANNELS, so the slicers draw
  // per channel maxima and slice2d samples the channels, not stacks of its own.
  bool drawsChannels() const override { return channels_ != nullptr; }

  const lod::BrickGrid& grid() const override { return grid_; }
  const lod::MultiresSource& source() const { return *source_; }
  const BricksHostSplit& hostSplit() const { return hostSplit_; }
  int slotCount() const override { return static_cast<int>(slotKey_.size()); }
  lod::StreamerStats streamerStats() const override { return streamer_->stats(); }
  void retryFailingReads(bool retry) override {
    retryFailing_ = retry;
    streamer_->retryFailing(retry);
    for (auto& s : channelStreamers_) s->retryFailing(retry);
  }
  void setUpdatePace(const UpdatePace& pace) override {
    options_.uploadMsPerFrame = pace.uploadMs;
    options_.uploadBytesPerFrame = pace.uploadBytes;
    inlineReads_ = pace.inlineReads;
    streamer_->setInlineReadsPerRequest(pace.inlineReads);
    for (auto& s : channelStreamers_) s->setInlineReadsPerRequest(pace.inlineReads);
  }
  bool replaceSources(std::vector<std::shared_ptr<const lod::MultiresSource>> sources) override;
  // How many times replaceSources() has streamed other pyramids in.
  int sourcesReplaced() const { return sourcesReplaced_; }
  // The page table as uploaded (RGBA texels, row 0 first; cell c at
  // pageGeometry().addressOf(c)): the CPU twin of the lookup in bricks.glsl
  // reads it.
  const std::vector<std::uint8_t>& pageTable() const { return pages_host_; }
  std::vector<int> cellLevels() const override;
  const MosaicLayout::Geometry& pageGeometry() const { return pageGeometry_; }
  glm::ivec3 atlasTexels() const { return atlasTexels_; }  // ES 2: of each texture
  // Where level-0 continuous voxel coordinate x0 is read: the atlas texel
  // coordinate (3D, continuous) and the level, or level -1 and the constant
  // stored value in texel.x. The CPU twin of bricks.glsl's address maths.
  struct Lookup {
    int level = 0;
    int texture = 0;  // ES 2: which atlas texture
    glm::dvec3 texel{0.0};
  };
  Lookup lookup(glm::dvec3 x0) const;

  static LayoutEntry registration();

 private:
  BricksLayout() = default;
  static std::unique_ptr<BricksLayout> build(
      std::vector<std::shared_ptr<const lod::MultiresSource>> sources, const ChannelSet* set,
      const gpu::DeviceLimits& limits, gpu::MemoryLedger& ledger, const BricksOptions& options);
  // Every channel's brick `key` when all are cached (readNow: read them
  // now), else empty.
  std::vector<std::shared_ptr<const lod::StoredBrick>> channelBricks(const lod::BrickKey& key,
                                                                     bool readNow);
  void bindChannels(const gpu::Program& program, int firstUnit) const;
  // The streamers over `sources` (one per channel), their caches within
  // the host split, and the channels' packing of their values.
  void streamFrom(const std::vector<std::shared_ptr<const lod::MultiresSource>>& sources);
  // The coarsest level read and uploaded into the first free slots, pinned.
  void pinCoarsest();
  // The channel atlases (layout/ChannelBricks.cpp): per group of four
  // channels one 3D texture (ES 3) or slots.x mosaics (ES 2), atlases_[k *
  // groups + g]; the units they take; the mosaics per group; their GLSL.
  void createChannelAtlases(gpu::MemoryLedger& ledger, gpu::TexelFormat format, glm::ivec3 slots,
                            const MosaicLayout::Geometry& mosaic, int stored);
  int channelUnits() const;
  int channelMosaics() const;
  gpu::ShaderPart channelsGlsl() const;
  void uploadChannels(int slot, const std::vector<std::shared_ptr<const lod::StoredBrick>>& bricks);
  bool channelsTransparent(const lod::BrickKey& key, const TransferFunction& tf,
                           bool exactOnly) const;
  int slotFor(std::uint64_t id, std::uint64_t frame);
  void upload(int slot, const lod::StoredBrick& brick);
  void keepFineRanges(int slot, const lod::StoredBrick& brick);
  // Whether the TF makes the brick transparent: by its own range read
  // (exactOnly, for the page table), or else the brick and every brick
  // under it by subtreeBound() (for the level selection, which leaves such
  // a brick's whole subtree out).
  bool transparent(const lod::BrickKey& key, const TransferFunction& tf, bool exactOnly,
                   std::uint16_t* value) const;
  std::optional<lod::BrickRange> subtreeBound(const lod::BrickKey& key,
                                              const lod::BrickStreamer& streamer) const;
  void rebuildPages(const TransferFunction& tf, BricksFrame& frame);
  glm::ivec3 slotOrigin(int slot) const;

  LayoutPlan plan_;
  BricksOptions options_;
  BricksHostSplit hostSplit_;
  gpu::ApiLevel api_ = gpu::ApiLevel::Gles3;
  std::shared_ptr<const lod::MultiresSource> source_;
  lod::BrickGrid grid_;
  std::unique_ptr<lod::BrickStreamer> streamer_;
  // Channels: the streamers of channels 1.. (streamer_ reads channel 0), the set
  // and the atlas format (gpu::TexelFormat) the channels are packed in.
  std::vector<std::unique_ptr<lod::BrickStreamer>> channelStreamers_;
  const ChannelSet* channels_ = nullptr;
  gpu::TexelFormat channelFormat_ = gpu::TexelFormat::RGBA8;
  // Per channel the stored values 0 and 1 of its texel component: the whole
  // stored range in 16 bits; in 8 bits (ES 2) the source's value range, so
  // that 100..3000 of a u16 channel keeps 8 bits, not 8 bits of 0..65535.
  std::vector<glm::dvec2> channelPacking_;
  std::vector<gpu::Texture> atlases_;  // ES 3: one 3D texture; ES 2: 1..8 mosaics
  gpu::Texture pages_;
  MosaicLayout::Geometry pageGeometry_;  // the page table's tiles (pageTableGeometry)
  // ES 3, filtered atlas, isotropic pyramid: the walk's map per cell (RGBA32F).
  gpu::Texture walkPages_;
  std::vector<float> walkHost_;
  MosaicLayout::Geometry mosaic_;  // ES 2: the atlas' z-slices as tiles
  glm::ivec3 slotGrid_{1};
  glm::ivec3 atlasTexels_{0};
  std::vector<std::int64_t> slotKey_;    // brick id per slot, -1 free
  std::vector<std::uint64_t> slotUsed_;  // frame last wanted
  std::vector<bool> slotPinned_;
  // Per slot holding a level-0 brick: (min, max) stored values of each
  // kFineBlock^3 block with its one-voxel support (valueBlocks()).
  static constexpr int kFineBlock = 8;
  std::vector<std::vector<std::uint16_t>> slotFine_;
  std::unordered_map<std::uint64_t, int> slotOf_;
  std::vector<std::uint8_t> pages_host_;
  std::vector<std::uint16_t> cellMin_, cellMax_;  // stored range of what each cell samples
  std::uint64_t frame_ = 0;
  std::uint64_t contentVersion_ = 1;
  bool walk_ = true;
  int atlasTexel_ = 0;       // BRICKS_TEXEL: how bricks.glsl reads a stored value
  bool classified_ = false;  // update() has seen a TF: transparent() may judge bricks
  // What the streamers were told (kept for the streamers of replaceSources).
  bool retryFailing_ = true;
  int inlineReads_ = -1;  // -1: the streamer's default
  int sourcesReplaced_ = 0;
};

}  // namespace tessera::layout
