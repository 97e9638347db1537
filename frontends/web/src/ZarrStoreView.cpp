#include "ZarrStoreView.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "tessera/core/Timing.h"
#include "tessera/gpu/Draw.h"
#include "tessera/lod/MultiresVolumeSource.h"
#include "tessera/render/Overlay.h"
#include "tessera/session/BrickRefinement.h"

namespace tessera::web {

namespace {

// As the viewer core plans its uploads (viewer/Viewer.cpp).
constexpr int kPlanImageSize = 1024;
constexpr int kSkipBlock = 8;
// Streaming (reading and uploading arrived bricks) before a frame is drawn.
constexpr double kStreamMs = 150.0;
// The preview's share of the budget, and its least resolution. The preview
// answers input that has already waited (for the strip running when it
// came, a wheel turn for its animation frame: up to 17 ms), so it takes
// about a third of the budget, leaving the input's wait and the
// presentation within two budgets. It keeps the full frame's sample
// distance: another would rebuild the ray caster's tables (classification
// per block) twice per preview, costing more than the preview itself.
constexpr double kPreviewShare = 0.35;
constexpr double kPreviewMinScale = 1.0 / 16.0;
// Its sizes on a ladder of quarter octaves: the ray caster keeps a target
// per size (Raycaster::useTarget), and a new one is a texture allocated and
// checked (two glGetError round trips) and a framebuffer checked, about
// 1 ms inside the input's latency. With any size, nearly every preview
// that answered input made one (22 of 24 in a latency run through the X
// server).
constexpr double kPreviewStepsPerOctave = 4.0;
// The first strip's rows (a fraction of the frame) before any cost is known.
constexpr double kFirstStrip = 1.0 / 64.0;

}  // namespace

FetchedZarrSource::FetchedZarrSource(std::shared_ptr<const ZarrStore> store,
                                     std::shared_ptr<const FetchStorage> storage)
    : zarr_(store), store_(std::move(store)), storage_(std::move(storage)) {}

bool FetchedZarrSource::prefetch(int level, const lod::VoxelBox& box) const {
  // Lists every read the box lacks (a sharded level's index first, then
  // its inner chunks' ranges).
  try {
    return store_->holdsReads(level, box.begin, box.end, [&](const ZarrStoredRead& read) {
      return storage_->ready(FetchStorage::keyOf(read));
    });
  } catch (const KeyNotFetched&) {
    return false;
  } catch (const std::exception&) {
    // A shard index that failed or is corrupt: the read reports it (the
    // brick fails, naming the key) as a failed chunk's does.
    return true;
  }
}

bool FetchedZarrSource::resident(int level, const lod::VoxelBox& box) const {
  bool all = true;
  try {
    store_->holdsReads(level, box.begin, box.end, [&](const ZarrStoredRead& read) {
      all = all && storage_->holds(FetchStorage::keyOf(read));
      return all;
    });
  } catch (const std::exception&) {
    return false;
  }
  return all;
}

ZarrStoreView::ZarrStoreView(gpu::GlContext& context, const gpu::DeviceLimits& limits,
                             const std::string& url, std::uint64_t cacheBytes)
    : context_(context),
      limits_(limits),
      storage_(std::make_shared<FetchStorage>(url, cacheBytes)) {}

ZarrStoreView::ZarrStoreView(gpu::GlContext& context, const gpu::DeviceLimits& limits, Host host)
    : context_(context),
      limits_(limits),
      storage_(std::move(host.storage)),
      store_(std::move(host.store)),
      source_(std::move(host.source)),
      times_(std::move(host.times)) {}

bool ZarrStoreView::open() {
  if (isOpen()) return true;
  // Each step throws while a key it reads has not arrived; then the keys
  // it wanted are fetched and the step runs again.
  try {
    if (!store_) store_ = std::make_shared<const ZarrStore>(storage_);
    if (!source_) source_ = std::make_shared<const FetchedZarrSource>(store_, storage_);
    const int top = store_->levelCount() - 1;
    const lod::VoxelBox all{glm::ivec3(0), store_->level(top).dims};
    if (!source_->prefetch(top, all)) return false;
    coarsest_ = source_->readBox(top, all);
    time_ = store_->selection().time;
    shown_ = source_;
    times_[time_] = source_;
    createBricks();
  } catch (const std::exception&) {
    if (storage_->hasWanted()) return false;
    throw;
  }
  compositor_ = std::make_unique<render::HybridCompositor>(context_);
  return true;
}

// The ray caster over the bricks layout of the time point shown.
void ZarrStoreView::createBricks() {
  const lod::MultiresVolumeSource volumeSource(shown_);
  active_ = render::createTechnique(
      "raycast", context_, limits_, volumeSource,
      {.imageSize = {kPlanImageSize, kPlanImageSize}, .skipBlock = kSkipBlock}, "bricks");
  bricks_ = active_.upload.layout ? active_.upload.layout->streaming() : nullptr;
  if (!bricks_) throw Error(storage_->describe() + ": the bricks layout was not created");
  active_.technique->setFusion(fused_);
}

std::shared_ptr<const FetchedZarrSource> ZarrStoreView::sourceAt(int time) {
  if (!store_) throw Error(storage_->describe() + ": the store is not open yet");
  auto it = times_.find(time);
  if (it != times_.end()) return it->second;
  if (time < 0 || time >= store_->timePoints()) {
    throw InputError(storage_->describe() + ": time point " + std::to_string(time) +
                     " asked for, the store has " + std::to_string(store_->timePoints()));
  }
  auto store = std::make_shared<const ZarrStore>(
      storage_, ZarrSelection{.time = time, .channel = store_->selection().channel});
  auto source = std::make_shared<const FetchedZarrSource>(std::move(store), storage_);
  return times_.emplace(time, std::move(source)).first->second;
}

void ZarrStoreView::showTime(int time) {
  if (time == time_ && shown_) return;
  std::shared_ptr<const FetchedZarrSource> next = sourceAt(time);
  const int top = next->levelCount() - 1;
  if (!next->resident(top, {glm::ivec3(0), next->levelInfo(top).dims})) {
    throw Error(storage_->describe() + ": time point " + std::to_string(time) +
                ": its coarsest level has not arrived");
  }
  pending_ = {};
  active_ = {};  // the time point before's atlas, page table and ray caster
  bricks_ = nullptr;
  shown_ = std::move(next);
  time_ = time;
  createBricks();
  shownBricks_ = {};
  shownVersion_ = 0;
  tablesVersion_ = ~std::uint64_t(0);
  tfRevision_ = ~std::uint64_t(0);  // the new ray caster takes the TF at the next frame
  framedWhole_ = false;
}

bool ZarrStoreView::finished(int time) const {
  return time == time_ && framedWhole_ && !pending_.active && shownBricks_.complete;
}

void ZarrStoreView::setFusion(std::shared_ptr<const FusedVolume> fused) {
  if (fused == fused_) return;
  fused_ = std::move(fused);
  if (active_.technique) active_.technique->setFusion(fused_);
}

StoreFrame ZarrStoreView::frame(const Camera& viewerCamera, const RenderSettings& settings,
                                const TransferFunction& tf, std::uint64_t tfRevision, bool box,
                                bool axes, int width, int height, int maxVolumePixels,
                                const std::vector<render::OverlayLine>& marks,
                                const StorePace& pace) {
  const auto t0 = std::chrono::steady_clock::now();
  layout::BricksFrame bricks = pending_.active ? pending_.bricks : shownBricks_;
  bricks.uploaded = 0;  // by this frame
  pending_ = {};
  StoreFrame f;
  if (tfRevision != tfRevision_) {
    active_.technique->setTransferFunction(tf);
    tfRevision_ = tfRevision;
  }
  // The viewer's orbit, zoom and pan, framed on this volume.
  FrameView v{.camera = viewerCamera, .pass = settings, .tf = tf};
  const Volume& shape = store_->shape();
  v.camera.frame(shape);
  double scale = 1.0;
  const double pixels = static_cast<double>(width) * height;
  if (maxVolumePixels > 0 && pixels > maxVolumePixels) scale = std::sqrt(maxVolumePixels / pixels);
  v.width = width;
  v.height = height;
  v.renderWidth = std::max(1, static_cast<int>(std::lround(width * scale)));
  v.renderHeight = std::max(1, static_cast<int>(std::lround(height * scale)));
  // Over transparent black; the compositor adds the background and lines.
  v.background = glm::vec4(settings.background);
  v.pass.background = glm::dvec4(0.0);
  render::OverlayOptions overlays;
  overlays.box = box;
  overlays.axes = axes;
  std::vector<render::OverlayLine> lines = render::overlayLines(shape, overlays);
  lines.insert(lines.end(), marks.begin(), marks.end());
  compositor_->setOverlayLines(std::move(lines));
  f.renderWidth = v.renderWidth;
  f.renderHeight = v.renderHeight;
  // Errors that other drawing left are forgotten, not blamed on the store
  // (those of a preview left unasked are reported: gpu::leaveErrorsUnasked);
  // a call answering input skips the round trip (its wait is the input's):
  // while a store is drawn its view is the page's only GL user (the
  // in-core viewer and a store's channels draw when no store is drawn).
  const bool answersInput = pace.inputWaitedMs >= 0.0;
  if (!answersInput) gpu::clearErrors();
  budgetMs_ = pace.budgetMs;
  stripShare_ = pace.stripShare;
  if (!pace.progressive) {
    bricks_->setUpdatePace({});
    // A ray march costs far more than an update (SwiftShader: most of a
    // second), so stream for up to kStreamMs before drawing, and a frame
    // shows everything that has arrived; the page fetches between frames.
    f.bricks = stream(v, kStreamMs);
    f.uploadedNow = f.bricks.uploaded;
    f.streamed = true;
    f.streamMs = msSince(t0);
    return drawWhole(v, f, t0);
  }
  const double wholeMs = msPerPixel_ * v.renderWidth * v.renderHeight;
  if (msPerPixel_ > 0.0 && wholeMs <= 0.5 * budgetMs_) {
    bricks_->setUpdatePace(streamPace());
    f.bricks = stream(v, 0.0);
    f.uploadedNow = f.bricks.uploaded;
    f.streamed = true;
    f.streamMs = msSince(t0);
    return drawWhole(v, f, t0);
  }
  pending_ = {.active = true,
              .streaming = true,
              .viewChanged = pace.viewChanged,
              .view = v,
              .bricks = bricks};
  f.bricks = bricks;
  if (pace.viewChanged) {
    // Input is answered by a preview of what is on the GPU, seen from the
    // new view, and nothing else: the new view's selection, requests,
    // uploads and page table (which would also rebuild the ray caster's
    // tables inside the preview) are the pending frame's first steps, one
    // animation frame later. The store's first frame has nothing on the
    // GPU to preview: it selects first (the coarsest bricks, resident from
    // the open, are then what it shows).
    if (shownBricks_.cellsPerLevel.empty()) {
      bricks_->setUpdatePace({.uploadMs = 0.0, .uploadBytes = 0, .inlineReads = 0});
      pending_.bricks = f.bricks = stream(v, 0.0);
      f.uploadedNow = f.bricks.uploaded;
      f.streamed = true;
      f.streamMs = msSince(t0);
    }
    f.setupMs = msSince(t0) - f.streamMs;
    preview(v, f, answersInput ? pace.inputWaitedMs + msSince(t0) : -1.0);
  }
  f.pending = true;
  f.ms = msSince(t0);
  return f;
}

// A budget-sized streaming step: one update that reads a brick and uploads
// one (an upload's cost is mostly the GPU's, which a time limit on the
// calls does not see).
layout::UpdatePace ZarrStoreView::streamPace() const {
  return {.uploadMs = 0.5 * budgetMs_, .uploadBytes = 1, .inlineReads = 1};
}

layout::BricksFrame ZarrStoreView::stream(const FrameView& v, double ms) {
  shownBricks_ = session::BrickRefinement(*bricks_).step(v.camera, v.renderWidth, v.renderHeight,
                                                         v.tf, {.streamMs = ms, .idleWaitMs = 0.0});
  return shownBricks_;
}

void ZarrStoreView::show(const gpu::Texture& image, const FrameView& v) {
  compositor_->composeInto(image, v.camera, v.background, store_->shape().extent(), 0,
                           glm::ivec4(0, 0, v.width, v.height));
  // Waits for the frame (glFinish does not); the callers ask for its errors
  // once, after this read-back (gpu::DeferredErrorChecks).
  std::uint8_t pixel[4];
  gpu::readPixelsRgba8({0, 0, 1, 1}, pixel);
}

StoreFrame ZarrStoreView::drawWhole(const FrameView& v, StoreFrame f,
                                    std::chrono::steady_clock::time_point t0) {
  gpu::DeferredErrorChecks deferred("OME-Zarr frame");
  f.tablesMs = prepareTables(v);
  const auto t1 = std::chrono::steady_clock::now();
  show(active_.technique->render(v.camera, v.pass, v.renderWidth, v.renderHeight, 0.0), v);
  deferred.check("OME-Zarr frame");
  shownVersion_ = active_.upload.layout->contentVersion();
  framedWhole_ = true;
  msPerPixel_ = msSince(t1) / (static_cast<double>(v.renderWidth) * v.renderHeight);
  f.shown = true;
  f.ms = msSince(t0);
  return f;
}

bool ZarrStoreView::tablesStale() const {
  return active_.upload.layout->contentVersion() != tablesVersion_;
}

// The ray caster's tables for `v` (rebuilt when bricks changed what it
// samples: its empty-space blocks), apart from its ray march; ms.
double ZarrStoreView::prepareTables(const FrameView& v) {
  const auto t0 = std::chrono::steady_clock::now();
  active_.technique->prepare(v.camera, v.pass);
  tablesVersion_ = active_.upload.layout->contentVersion();
  return msSince(t0);
}

// At the resolution that met the preview's share of the budget before
// (render::QualityController's feedback; the first at the least). One
// answering an input that waited `inputWaitedMs` (negative: none) takes at
// most what is left of two budgets since the input's stamp (less work when
// that is under its share; its time then not fed back), and leaves its GL
// errors to the next call: each glGetError is a round trip to the GPU
// process (0.3-0.6 ms on SwiftShader), inside the input's latency.
void ZarrStoreView::preview(const FrameView& v, StoreFrame& f, double inputWaitedMs) {
  if (!previewQuality_) {
    previewQuality_ = std::make_unique<render::QualityController>(
        render::QualityController::Options{.goalMs = kPreviewShare * budgetMs_,
                                           .minResolutionScale = kPreviewMinScale,
                                           .maxStepScale = 1.0,
                                           .resolutionStepsPerOctave = kPreviewStepsPerOctave});
    previewQuality_->setInteracting(true);
  }
  const double shareMs = kPreviewShare * budgetMs_;
  const double dueMs = inputWaitedMs >= 0.0 ? 2.0 * budgetMs_ - inputWaitedMs : shareMs;
  const bool hurried = previewMeasured_ && dueMs < shareMs;
  const render::QualityLevel level = !previewMeasured_ ? previewQuality_->levelFor(0.0)
                                     : hurried         ? previewQuality_->nextWithin(dueMs)
                                                       : previewQuality_->next();
  FrameView p = v;
  p.renderWidth = std::max(1, static_cast<int>(std::lround(v.renderWidth * level.resolutionScale)));
  p.renderHeight =
      std::max(1, static_cast<int>(std::lround(v.renderHeight * level.resolutionScale)));
  // Its passes' errors are asked for once, after the read-back that waits
  // for them (each glGetError is a round trip to the browser's GPU process);
  // one answering input leaves them to the next check that waits anyway (a
  // strip's read-back, an upload's), which reports them in its name too:
  // asked at the next animation frame, the query waited for the GPU
  // process's composition of the page (a median 5.5 ms, up to 23 ms).
  gpu::DeferredErrorChecks deferred("OME-Zarr preview");
  f.tablesRebuilt = tablesStale();
  f.tablesMs = prepareTables(v);
  const auto t0 = std::chrono::steady_clock::now();
  show(active_.technique->render(p.camera, p.pass, p.renderWidth, p.renderHeight, 0.0), p);
  if (inputWaitedMs < 0.0) deferred.check("OME-Zarr preview");
  f.previewMs = msSince(t0);
  if (!hurried) previewQuality_->report(level, f.previewMs);
  previewMeasured_ = true;
  f.shown = true;
  f.previewWidth = p.renderWidth;
  f.previewHeight = p.renderHeight;
}

StoreFrame ZarrStoreView::refine() {
  if (!pending_.active) return {};
  const auto t0 = std::chrono::steady_clock::now();
  Pending& p = pending_;
  // No gpu::clearErrors() here: each query waits for the browser's GPU
  // process. A step asks for its errors where it waits anyway (a strip's
  // read-back, an upload's), and they include what a preview that answered
  // input left unasked (gpu::leaveErrorsUnasked).
  if (!p.streaming) {
    if (!tablesStale()) return strip();
    // The bricks changed what the ray caster samples since its tables were
    // built, outside a streaming step (which rebuilds them itself): they
    // are rebuilt in a step of their own, not in a strip or in the preview
    // that answers the next input.
    // Its uploads waited for here, as a streaming step's: this step's
    // cost, not the next one's (the preview that answers input).
    StoreFrame f;
    f.tablesRebuilt = true;
    f.tablesMs = prepareTables(p.view);
    gpu::checkErrors("OME-Zarr tables");
    f.pending = true;
    f.bricks = p.bricks;
    f.renderWidth = p.view.renderWidth;
    f.renderHeight = p.view.renderHeight;
    f.ms = msSince(t0);
    return f;
  }
  // What arrived, streamed in budget-sized steps up to as long as a whole
  // frame streams before it draws (while they make progress); the bricks
  // then stay as they are until the frame is drawn.
  const std::uint64_t read = bricks_->streamerStats().bricksRead;
  const int uploadedBefore = p.bricks.uploaded;
  bricks_->setUpdatePace(streamPace());
  p.bricks = stream(p.view, 0.0);
  StoreFrame f;
  f.updateMs = msSince(t0);
  // Bricks that arrived, or the new view's levels, change what the ray
  // caster samples: its tables (empty-space blocks) are rebuilt in this
  // step, so that the preview answering the next input never pays for
  // them (rebuilt in a step of their own after the streaming, 2-3 of a
  // drag's 53 previews did, 3-5 ms each).
  f.tablesRebuilt = tablesStale();
  if (f.tablesRebuilt) f.tablesMs = prepareTables(p.view);
  // An upload (bricks, the blocks' texture) is done in the browser's GPU
  // process after this call returns: waited for here, it is this step's
  // cost, not the next one's. Without one there is nothing to wait for (a
  // query would wait for whatever the GPU process does meanwhile, such as
  // composing the page).
  if (p.bricks.uploaded > 0 || f.tablesRebuilt) gpu::checkErrors("OME-Zarr streaming");
  f.uploadWaitMs = msSince(t0) - f.updateMs - f.tablesMs;
  f.uploadedNow = p.bricks.uploaded;
  p.bricks.uploaded += uploadedBefore;
  p.streamedMs += msSince(t0);
  const bool progress =
      p.bricks.uploaded > uploadedBefore || bricks_->streamerStats().bricksRead != read;
  if (p.bricks.complete || !progress || p.streamedMs >= kStreamMs) p.streaming = false;
  f.pending = true;
  f.streamed = true;
  f.bricks = p.bricks;
  f.renderWidth = p.view.renderWidth;
  f.renderHeight = p.view.renderHeight;
  if (!p.streaming && !p.viewChanged && active_.upload.layout->contentVersion() == shownVersion_) {
    // Nothing new to draw: the canvas shows this view of these bricks.
    f.pending = false;
    pending_ = {};
  }
  f.ms = f.streamMs = msSince(t0);
  return f;
}

// One strip of about the budget, sized by the cost per pixel of the strips
// before (as viewer::Viewer::refine sizes its strips).
StoreFrame ZarrStoreView::strip() {
  const auto t0 = std::chrono::steady_clock::now();
  Pending& p = pending_;
  const FrameView& v = p.view;
  const double pixels = static_cast<double>(v.renderWidth) * v.renderHeight;
  const double minStrip = 1.0 / v.renderHeight;
  // Strips are sized by what their rows cost (render::RowCosts: rows across
  // the volume's box are dear, those beside it cheap), so that a cost learnt
  // on the rows below the volume does not size a strip across it several
  // budgets long.
  if (p.costs.empty()) {
    p.costs = render::RowCosts(v.camera, store_->shape().extent(), v.renderWidth, v.renderHeight);
    if (msPerWeight_ <= 0.0 && msPerPixel_ > 0.0) {
      msPerWeight_ = msPerPixel_ * pixels / p.costs.weight(0.0, 1.0);
    }
  }
  double rows = kFirstStrip;
  if (msPerWeight_ > 0.0) {
    double weight = stripShare_ * budgetMs_ / msPerWeight_;
    // At most twice the last strip's weight: the rows above may cover
    // denser parts of the volume than those the cost was learnt on.
    if (p.weight > 0.0) weight = std::min(weight, 2.0 * p.weight);
    rows = p.costs.reach(p.done, weight) - p.done;
  }
  rows = std::clamp(rows, minStrip, 1.0 - p.done);
  if (1.0 - (p.done + rows) < 0.5 * minStrip) rows = 1.0 - p.done;
  gpu::DeferredErrorChecks deferred("OME-Zarr strip");  // asked once, after the read-back
  const double tablesMs = prepareTables(v);
  const gpu::Texture* image = nullptr;
  {
    const gpu::RegionScope region(
        glm::vec4(0.0f, static_cast<float>(p.done), 1.0f, static_cast<float>(p.done + rows)));
    image = &active_.technique->render(v.camera, v.pass, v.renderWidth, v.renderHeight, 0.0);
    std::uint8_t pixel[4];
    gpu::readPixelsRgba8({0, 0, 1, 1}, pixel);  // waits for the strip
  }
  deferred.check("OME-Zarr strip");
  // A strip's time varies with what its rows cover: a dearer one is taken
  // at once, a cheaper one only in part, so that strips overrun seldom.
  const double marchMs = msSince(t0) - tablesMs;
  const double perPixel = marchMs / (rows * pixels);
  msPerPixel_ = perPixel > msPerPixel_ ? perPixel : 0.75 * msPerPixel_ + 0.25 * perPixel;
  const double weight = p.costs.weight(p.done, p.done + rows);
  if (weight > 0.0) {
    const double perWeight = marchMs / weight;
    msPerWeight_ = perWeight > msPerWeight_ ? perWeight : 0.75 * msPerWeight_ + 0.25 * perWeight;
  }
  p.rows = rows;
  p.weight = weight;
  p.done = p.done + rows >= 1.0 - 1e-9 ? 1.0 : p.done + rows;
  StoreFrame f;
  f.tablesMs = tablesMs;
  f.stripRows = rows;
  f.bricks = p.bricks;
  f.renderWidth = v.renderWidth;
  f.renderHeight = v.renderHeight;
  f.pending = p.done < 1.0;
  if (!f.pending) {
    show(*image, v);
    deferred.check("OME-Zarr frame");
    shownVersion_ = active_.upload.layout->contentVersion();
    framedWhole_ = true;
    f.shown = true;
    pending_ = {};
  }
  f.ms = msSince(t0);
  return f;
}

}  // namespace tessera::web
