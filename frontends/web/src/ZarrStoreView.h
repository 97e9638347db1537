#pragma once
// An OME-Zarr store read over fetch() (ZarrFetchStorage.h) and rendered in
// the page through the bricks layout, coarse to fine: the same
// lod::LevelSelection and lod::BrickStreamer as `tessera render STORE`
// (layout/BricksLayout.h), whose reads never wait: a brick whose chunks
// have not arrived is skipped (MultiresSource::prefetch) and its chunks
// are listed for the page to fetch. The viewer core's camera, transfer
// function and render settings drive it, so the page's controls work on it.
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "ZarrFetchStorage.h"
#include "tessera/core/Camera.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/io/ZarrStore.h"
#include "tessera/layout/StreamingLayout.h"
#include "tessera/lod/ZarrMultiresSource.h"
#include "tessera/render/HybridCompositor.h"
#include "tessera/render/Overlay.h"
#include "tessera/render/QualityController.h"
#include "tessera/render/RowCosts.h"
#include "tessera/render/TechniqueRegistry.h"

namespace tessera::web {

// The stored bytes of the chunks a store view keeps (its FetchStorage's
// budget; compressed, so many chunks: a brick read with its apron touches
// its neighbours' chunks), and what a time series fetches ahead of the
// time point shown: half, so that the shown one's chunks are not let go
// for the next one's.
inline constexpr std::uint64_t kStoreFetchedBytes = 48ull << 20;
inline constexpr std::uint64_t kStoreFetchAheadBytes = kStoreFetchedBytes / 2;
// The least a page may set its stores' chunk cache to (?zarrcache=MiB).
inline constexpr std::uint64_t kStoreCacheMinBytes = 64ull << 10;
// The least share of the frame budget a page may give a store's strips
// (?stripshare=): below it a strip is mostly its fixed cost.
inline constexpr double kStoreStripShareMin = 0.05;

// A store's levels read through a FetchStorage: prefetch() lists the
// chunks a box needs that have not arrived.
class FetchedZarrSource final : public lod::MultiresSource {
 public:
  FetchedZarrSource(std::shared_ptr<const ZarrStore> store,
                    std::shared_ptr<const FetchStorage> storage);
  const Volume& shape() const override { return zarr_.shape(); }
  int levelCount() const override { return zarr_.levelCount(); }
  lod::LevelInfo levelInfo(int level) const override { return zarr_.levelInfo(level); }
  Volume readBox(int level, const lod::VoxelBox& box) const override {
    return zarr_.readBox(level, box);
  }
  bool prefetch(int level, const lod::VoxelBox& box) const override;
  // Whether every chunk of the box has arrived, asking for none.
  bool resident(int level, const lod::VoxelBox& box) const;
  std::string describe() const override { return zarr_.describe(); }

 private:
  lod::ZarrMultiresSource zarr_;
  std::shared_ptr<const ZarrStore> store_;
  std::shared_ptr<const FetchStorage> storage_;
};

struct StoreFrame {
  layout::BricksFrame bricks;  // as drawn (a pending frame: as it will be drawn)
  double ms = 0.0;             // this call's work
  double streamMs = 0.0;       // of which reading and uploading bricks
  int renderWidth = 0, renderHeight = 0;
  bool shown = false;     // drew on the canvas: a preview or the finished frame
  bool pending = false;   // the full frame is still to come (ZarrStoreView::refine)
  bool streamed = false;  // this call read and uploaded what had arrived
  int previewWidth = 0, previewHeight = 0;  // the preview this call showed, if any
  // Where this call's time went (the latency browser test reports them):
  // the layout's update (selection, requests, reads, uploads, page table),
  // the wait for its uploads in the GPU process, the ray caster's tables
  // rebuilt for bricks that changed, and the preview (ray march, compose,
  // wait); and a frame()'s own work before its preview (the view, the
  // transfer function, the overlay lines).
  double updateMs = 0.0, uploadWaitMs = 0.0, tablesMs = 0.0, previewMs = 0.0, setupMs = 0.0;
  // A strip's rows, as a fraction of the frame's (0: no strip).
  double stripRows = 0.0;
  // Bricks this call uploaded (bricks.uploaded: those of the pending frame).
  int uploadedNow = 0;
  // This call rebuilt the ray caster's tables for bricks that changed (its
  // empty-space blocks): a streaming or tables step's work, never a
  // preview's.
  bool tablesRebuilt = false;
};

// How store frames are paced, as the viewer core paces its progressive
// frames (viewer::Viewer::progressive, frameBudgetMs): a whole ray march
// costs up to seconds in software WebGL, so each call does about
// `budgetMs` of work and input is answered between calls.
struct StorePace {
  bool progressive = false;  // false: each frame streams and draws whole
  double budgetMs = 12.0;
  // A strip's share of the budget: its cost varies with what its rows cover
  // and with the GPU process's other work (the page's compositing), and an
  // input that arrives during one waits for it (strips of the whole budget
  // took up to 40 ms at a load of 5 on 2 cores; with half of it no run of
  // bench/web_latency.py kept every input within two budgets, with a
  // quarter 4 of 6 did). The page's ?stripshare= sets it
  // (tessera_zarr_set_strip_share), for comparisons.
  double stripShare = 0.25;
  // The view, the settings or the canvas changed: a preview at once. Else
  // (bricks arrived) the canvas keeps its image until the new one is done.
  bool viewChanged = true;
  // The input event this frame answers (a move, a release, a wheel turn):
  // how long it has waited since its time stamp (a wheel turn waits for
  // the animation frame Chromium dispatches it with), ms; negative: the
  // frame answers no input. Its preview is due within two budgets of the
  // stamp, and its GL errors are asked for by the next call.
  double inputWaitedMs = -1.0;
};

class ZarrStoreView {
 public:
  // What a store view holds in host memory: the fetched chunks, the store's
  // metadata and its levels, and the time points opened (sourceAt: those a
  // series plays, the same objects after a lost WebGL context).
  struct Host {
    std::shared_ptr<FetchStorage> storage;
    std::shared_ptr<const ZarrStore> store;
    std::shared_ptr<const FetchedZarrSource> source;
    std::map<int, std::shared_ptr<const FetchedZarrSource>> times;
  };

  // `cacheBytes`: the fetched chunks kept (FetchStorage's budget).
  ZarrStoreView(gpu::GlContext& context, const gpu::DeviceLimits& limits, const std::string& url,
                std::uint64_t cacheBytes = kStoreFetchedBytes);
  // A view of a store already read, on another context (the restored one
  // after a context loss): open() makes its atlas, page table and ray
  // caster again, and the bricks are read again from the chunks held (the
  // page fetches only those the host cache let go).
  ZarrStoreView(gpu::GlContext& context, const gpu::DeviceLimits& limits, Host host);
  Host host() const { return {storage_, store_, source_, times_}; }

  FetchStorage& storage() { return *storage_; }
  // One step of opening: the metadata, then the coarsest level (pinned in
  // the atlas). False while keys are wanted (storage().takeWanted(): the
  // page fetches them and calls again); throws the store's errors.
  bool open();
  bool isOpen() const { return active_.technique != nullptr; }
  const ZarrStore& store() const { return *store_; }
  const layout::StreamingLayout& bricks() const { return *bricks_; }
  // The store's levels; readBox of a box whose chunks have arrived
  // (prefetch true) reads without the network.
  const FetchedZarrSource& source() const { return *source_; }
  std::shared_ptr<const FetchedZarrSource> sharedSource() const { return source_; }
  // The store's t axis played over bricks (WebSessionTime.cpp). Time
  // point t's levels: the store's selection at t over the same fetched
  // keys, made on first use (its metadata read from the storage:
  // KeyNotFetched, the keys wanted, while they have not arrived).
  std::shared_ptr<const FetchedZarrSource> sourceAt(int time);
  // Draws time point t from now on through a bricks layout of its own, so
  // that no brick of another time point is drawn for it (the one before's
  // atlas and page table go first: the texture budget holds one). Its
  // coarsest level must have arrived (an Error naming the store if not).
  void showTime(int time);
  int timePoint() const { return time_; }
  // Whether a whole frame of time point t is on the canvas with every
  // brick the view wants (none coming, no frame pending): playback's next
  // time point waits for it (Session::stepPlayback).
  bool finished(int time) const;
  // The coarsest level, read once at open (for the page's histogram).
  const Volume& coarsest() const { return coarsest_; }
  // A second volume fused into the store's ray march (docs/fusion.md),
  // aligned with level 0 by world coordinates; null: none.
  void setFusion(std::shared_ptr<const FusedVolume> fused);

  // Selects levels for the view, uploads the bricks that arrived, requests
  // the missing ones (storage().takeWanted()), and draws into the canvas
  // (width x height), the volume at most maxVolumePixels (0: all) and
  // upscaled with the overlay lines as the viewer core draws them.
  // `marks`: more lines (level-0 model frame), composed by depth like the box.
  // Progressive (`pace`): when the whole frame would cost more than the
  // budget, one update and a preview within the budget (a changed view),
  // and the full frame follows through refine(); a new frame() cancels it.
  StoreFrame frame(const Camera& viewerCamera, const RenderSettings& settings,
                   const TransferFunction& tf, std::uint64_t tfRevision, bool box, bool axes,
                   int width, int height, int maxVolumePixels,
                   const std::vector<render::OverlayLine>& marks = {}, const StorePace& pace = {});
  // The pending full frame, about the budget per call: first streaming
  // what has arrived (up to as long as a whole frame streamed), then the
  // ray march in horizontal strips (gpu::RegionScope) into the technique's
  // target, shown once the last is drawn. The bricks do not change between
  // its strips, so the finished image is the whole frame's.
  StoreFrame refine();
  bool refining() const { return pending_.active; }

 private:
  gpu::GlContext& context_;
  gpu::DeviceLimits limits_;
  std::shared_ptr<FetchStorage> storage_;
  std::shared_ptr<const ZarrStore> store_;
  std::shared_ptr<const FetchedZarrSource> source_;
  // The time point drawn and its levels (source_'s until showTime), and
  // the others opened (sourceAt).
  int time_ = 0;
  std::shared_ptr<const FetchedZarrSource> shown_;
  std::map<int, std::shared_ptr<const FetchedZarrSource>> times_;
  bool framedWhole_ = false;  // a whole frame of time_ is on the canvas
  Volume coarsest_;
  render::TechniqueOnVolume active_;
  layout::StreamingLayout* bricks_ = nullptr;
  std::unique_ptr<render::HybridCompositor> compositor_;
  std::uint64_t tfRevision_ = 0;
  std::shared_ptr<const FusedVolume> fused_;

  // A frame of the view: what the technique renders and how it is shown.
  struct FrameView {
    Camera camera;  // framed on the store's shape
    RenderSettings pass;
    TransferFunction tf;
    glm::vec4 background{0.0f};
    int width = 0, height = 0;              // the canvas
    int renderWidth = 0, renderHeight = 0;  // the volume layer
  };
  struct Pending {
    bool active = false;
    bool streaming = true;  // still streaming; then strips
    bool viewChanged = true;
    FrameView view;
    layout::BricksFrame bricks;
    double streamedMs = 0.0;
    double done = 0.0;       // fraction of the rows drawn
    double rows = 0.0;       // the last strip's
    double weight = 0.0;     // the last strip's rows' weight (costs)
    render::RowCosts costs;  // the view's rows (at the first strip)
  };
  void createBricks();
  layout::UpdatePace streamPace() const;
  layout::BricksFrame stream(const FrameView& v, double ms);
  // The technique's image of `v` composed into the canvas, waited for.
  void show(const gpu::Texture& image, const FrameView& v);
  StoreFrame drawWhole(const FrameView& v, StoreFrame f, std::chrono::steady_clock::time_point t0);
  void preview(const FrameView& v, StoreFrame& f, double inputWaitedMs);
  double prepareTables(const FrameView& v);
  // The bricks changed what the ray caster samples since its tables were built.
  bool tablesStale() const;
  StoreFrame strip();
  Pending pending_;
  // What the last full frame on the canvas sampled (Layout::contentVersion).
  std::uint64_t shownVersion_ = 0;
  // What the ray caster's tables were last built for (prepareTables).
  std::uint64_t tablesVersion_ = ~std::uint64_t(0);
  layout::BricksFrame shownBricks_;  // the bricks' state after the last update
  double budgetMs_ = 12.0;
  double stripShare_ = StorePace{}.stripShare;
  double msPerPixel_ = 0.0;   // the ray march at full quality, from strips and whole frames
  double msPerWeight_ = 0.0;  // the same per unit of render::RowCosts weight, from strips
  // The preview's resolution and step, fed back to meet its share of the budget.
  std::unique_ptr<render::QualityController> previewQuality_;
  bool previewMeasured_ = false;
};

}  // namespace tessera::web
