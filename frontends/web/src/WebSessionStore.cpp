// The session's OME-Zarr store over fetch() (frontends/web/zarr-url.js drives it): the
// page fetches the keys a step wants and hands them over; the store renders
// through the bricks layout coarse to fine (ZarrStoreView.h) with the viewer
// core's camera, transfer function and settings. Its bread-slice region is
// read with bounded reads: only the level-0 chunks overlapping the box are
// fetched (asynchronously, by the page), then one readBox, never the level
// whole.
#include <algorithm>
#include <cstdio>

#include "WebSession.h"
#include "tessera/core/Error.h"
#include "tessera/core/Histogram.h"

namespace tessera::web {

ZarrStoreView& WebSession::theStore() {
  if (!zarr_) throw Error("no OME-Zarr store is open");
  return *zarr_;
}

const Volume* WebSession::storeOverview() {
  return zarr_ && zarr_->isOpen() ? &zarr_->coarsest() : nullptr;
}

void WebSession::beginStore(const std::string& url) {
  zoomStop();
  session_->endExploration();
  session_->drawPyramid(nullptr);
  zarr_ = std::make_unique<ZarrStoreView>(context(), viewer().limits(), url, storeCacheBytes_);
  storeReopened_ = false;
}

void WebSession::setStoreCacheBytes(double bytes) {
  if (!(bytes >= double(kStoreCacheMinBytes) && bytes <= double(kStoreFetchedBytes))) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "zarrcache %g MiB: a store's chunk cache takes %g to %g MiB (default %g)",
                  bytes / 1048576.0, double(kStoreCacheMinBytes) / 1048576.0,
                  double(kStoreFetchedBytes) / 1048576.0, double(kStoreFetchedBytes) / 1048576.0);
    throw InputError(text);
  }
  storeCacheBytes_ = static_cast<std::uint64_t>(bytes);
}

void WebSession::setStoreStripShare(double share) {
  if (!(share >= kStoreStripShareMin && share <= 1.0)) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "stripshare %g: a store's strips take %g to 1 of the frame budget (default %g)",
                  share, kStoreStripShareMin, StorePace{}.stripShare);
    throw InputError(text);
  }
  storeStripShare_ = share;
}

void WebSession::reopenStore(ZarrStoreView::Host host) {
  zarr_ = std::make_unique<ZarrStoreView>(context(), viewer().limits(), std::move(host));
  storeReopened_ = true;
}

// True once open (the coarsest level is on the GPU): its histogram goes to
// the TF editor and the camera frames it (a store opened again after a
// context loss keeps the restored camera).
bool WebSession::storeOpenStep() {
  ZarrStoreView& z = theStore();
  // After a context loss the region or grid block it showed is asked for in
  // the same step as the store's coarsest level (and shown at once when its
  // chunks are held): every chunk the restore reads is wanted, or marked
  // used, before any is fetched, so that the chunk cache makes room for
  // those it let go by letting others go, not the ones held for it.
  if (storeReopened_ && session_->regionAgainPending()) session_->showRegionAgain();
  if (!z.open()) return false;
  // What an overlay goes over and the probe reads. A store opened again
  // after a context loss keeps what the session drew: a series over bricks
  // plays on from the time point it showed (the session kept it; storeFrame
  // shows that time point through the new view's bricks).
  if (!storeReopened_ || !session_->streamedSeries()) session_->drawPyramid(z.sharedSource());
  viewer::Viewer& v = viewer();
  v.tfEditor().setHistogram(Histogram::compute(z.coarsest(), 256, z.store().shape().window()));
  if (!storeReopened_) v.resetCamera();
  // After a context loss: the region or grid block it showed, once its
  // level-0 chunks are held again (the page fetches those the cache let go).
  if (!session_->showRegionAgain()) return false;
  storeReopened_ = false;
  return true;
}

// The viewer core's volume shows again.
void WebSession::closeStore() {
  session_->drawPyramid(nullptr);  // its time series too, which reads through the store view
  zarr_.reset();
  session_->endExploration();
}

// Ends past the level are clamped; an empty box or one that starts outside
// is an error naming the store.
lod::VoxelBox WebSession::storeRegionBox(const lod::VoxelBox& asked) {
  ZarrStoreView& z = theStore();
  if (!z.isOpen()) throw Error(z.storage().describe() + ": the store is not open yet");
  return exploration().clampBox(asked, z.storage().describe() + ": region (level 0)");
}

// The explored pyramid's: the time point shown (WebSession::exploration).
bool WebSession::storeRegionPrefetch(const lod::VoxelBox& asked) {
  const lod::VoxelBox box = storeRegionBox(asked);
  return exploration().explorer().source().prefetch(0, box);
}

// Reads the box (its chunks fetched: storeRegionPrefetch) at level 0 of
// the time point the session shows and makes it the viewer's volume,
// placed and windowed as in the store (what `tessera render STORE --time T
// --region` reads); the page then draws the viewer
// instead of the store until it goes back to the store's overview. The
// grid's pending block is shown as the grid's; any other box as a region.
// Seen from the store view's direction, projection and zoom.
void WebSession::showStoreRegion(const lod::VoxelBox& asked) {
  ZarrStoreView& z = theStore();
  const lod::VoxelBox box = storeRegionBox(asked);
  session::Exploration& e = exploration();
  if (!e.explorer().source().prefetch(0, box)) {
    throw Error(z.storage().describe() + ": region: its chunks have not all arrived");
  }
  const auto& pending = e.pending();
  session::ExploreStep step =
      gridStoreWanted() && pending->box.begin == box.begin && pending->box.end == box.end
          ? *pending
          : e.region(box, session::Follow::Centre);
  step.follow = session::Follow::Centre;
  e.showIn(viewer(), e.read(step), step);
  viewer().setWindow(z.store().shape().window());
}

// Back to the store's overview from its region (the region stays known,
// for its outline in the slice views).
void WebSession::storeRegionOverview() {
  if (!regionShown()) return;
  viewer().camera() = explore()->overviewCamera();
  explore()->overviewShown();
}

std::optional<lod::VoxelBox> WebSession::storeGridBlock() {
  if (!storeOverview() || !explore() || gridStoreWanted() || regionShown()) return std::nullopt;
  return explore()->gridBlock();
}

StoreFrame WebSession::storeFrame(int width, int height, bool viewChanged, double inputWaitedMs) {
  viewer::Viewer& v = viewer();
  ZarrStoreView& z = theStore();
  // The store's t axis over bricks (WebSessionTime.cpp): the time point
  // the session shows is drawn, through its own bricks.
  if (session_->streamedSeries() && z.timePoint() != session_->timePoint()) {
    z.showTime(session_->timePoint());
  }
  // The picked region (red) and the grid view's last block (cyan) over the
  // store, level-0 voxels, as over a file's overview (applyMarkBoxes),
  // composed by depth.
  std::vector<render::OverlayLine> marks;
  const Volume& shape = z.store().shape();
  if (explore() && explore()->picked()) {
    marks = viewer::boxLines(*explore()->picked(), shape.dims(), shape.extent(),
                             session::kRegionColour);
  }
  if (const std::optional<lod::VoxelBox> block = storeGridBlock()) {
    const auto cyan =
        viewer::boxLines(*block, shape.dims(), shape.extent(), session::kGridBlockColour);
    marks.insert(marks.end(), cyan.begin(), cyan.end());
  }
  const session::Overlay* overlay = session_->overlay();
  z.setFusion(overlay ? overlay->fused : nullptr);  // fused in the store's ray march
  return z.frame(v.camera(), v.frameSettings(), v.tfEditor().transferFunction(),
                 v.tfEditor().revision(), v.showBoundingBox, v.showAxes, width, height,
                 v.maxVolumePixels, marks,
                 {.progressive = v.progressive,
                  .budgetMs = v.frameBudgetMs,
                  .stripShare = storeStripShare_,
                  .viewChanged = viewChanged,
                  .inputWaitedMs = inputWaitedMs});
}

}  // namespace tessera::web

namespace tessera::web {

bool WebSession::storeTimeFinished() {
  // A region or grid block of the store is the viewer's frame (the
  // session reads it again from each time point once its chunks arrived).
  if (!zarr_ || !session_->streamedSeries() || storeRegionShown()) return true;
  // Being opened again after a context loss: the time point shown is not
  // on the canvas yet, and playback waits for it.
  if (!zarr_->isOpen()) return false;
  return zarr_->finished(session_->timePoint());
}

}  // namespace tessera::web
