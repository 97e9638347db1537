// A session over a lost GPU context (Session::loseContext, restoreContext,
// showRegionAgain): what the view showed is kept in host memory while the
// context is gone and made again on the next one, nothing read again. The
// web page calls these when the browser takes its WebGL context away and
// gives it back (frontends/web/src/WebSession.cpp recoverContext); a
// desktop front end would after a GPU reset.
#include <utility>

#include "tessera/core/Error.h"
#include "tessera/session/Session.h"

namespace tessera::session {

Session::ViewKnobs Session::ViewKnobs::of(viewer::Viewer& view) {
  ViewKnobs k;
  k.quality = view.quality;
  k.maxVolumePixels = view.maxVolumePixels;
  k.showBoundingBox = view.showBoundingBox;
  k.showAxes = view.showAxes;
  k.progressive = view.progressive;
  k.frameBudgetMs = view.frameBudgetMs;
  k.clipPlaneFollowsCamera = view.clipPlaneFollowsCamera;
  k.followingPlaneDistance = view.followingPlaneDistance;
  if (view.labelsOn()) k.labels = view.labelTable();
  k.adaptive = view.qualityController().options();
  return k;
}

void Session::ViewKnobs::applyTo(viewer::Viewer& view) const {
  view.quality = quality;
  view.maxVolumePixels = maxVolumePixels;
  view.showBoundingBox = showBoundingBox;
  view.showAxes = showAxes;
  view.progressive = progressive;
  view.frameBudgetMs = frameBudgetMs;
  view.clipPlaneFollowsCamera = clipPlaneFollowsCamera;
  view.followingPlaneDistance = followingPlaneDistance;
  if (labels && view.hasVolume()) view.setLabels(*labels);
  view.qualityController() = render::QualityController(adaptive);
}

// The GL objects are deleted on the old context: where it is really gone
// (WebGL) that only raises errors, which the caller clears on the new one.
void Session::loseContext() {
  if (lost_) return;
  makeCurrent();
  Lost lost;
  if (view_) {
    lost.hadView = true;
    settings_ = currentSettings();  // the TF, window, camera and look the user set there
    lost.knobs = ViewKnobs::of(*view_);
    lost.camera = view_->camera();
    // A region or grid block is the view's volume, not the session's.
    const Exploration* e = exploration_.get();
    if (e && e->mode() != ExploreMode::Overview && e->shown() && view_->hasVolume() &&
        view_->volumeName() == e->shownName()) {
      again_ =
          RegionAgain{{*e->shown(), e->mode(), Follow::Keep}, view_->camera(), view_->window()};
    }
  }
  if (channelView_) lost.channels = channelView_->takeShown();
  if (exploration_) exploration_->endZoom();
  resident_.reset();
  channelView_.reset();
  streamedFrames_.reset();  // a series over bricks: drawn again from its time point's pyramid
  view_.reset();
  device_.context.reset();
  lost_ = std::move(lost);
}

void Session::restoreContext(gpu::DeviceSession device) {
  if (!lost_) throw GpuError("restoreContext: the session's GPU context was not lost");
  if (!device.context) throw GpuError("restoreContext: no context to restore onto");
  Lost lost = std::move(*lost_);
  lost_.reset();
  device_ = std::move(device);
  makeCurrent();
  applyVolumeSettings();  // the window the view had, on the volume it shares
  if (lost.hadView) {
    viewer::Viewer& v = view();  // the session's volume shared again, the settings applied
    lost.knobs.applyTo(v);
    v.camera() = lost.camera;
  }
  if (lost.channels) channelView().show(std::move(lost.channels->set), lost.channels->name);
  // A pyramid the front end draws is shown by it first (its own GPU side).
  if (!drawn_) showRegionAgain();
}

bool Session::showRegionAgain() {
  if (!again_) return true;
  if (!exploration_ || !view_) {
    again_.reset();
    return true;
  }
  const RegionAgain& r = *again_;
  if (!exploration_->explorer().source().prefetch(0, r.step.box)) return false;
  makeCurrent();
  // Still in the block's mode: the overview's camera stays the one to go back to.
  exploration_->showIn(*view_, exploration_->read(r.step), r.step);
  view_->setWindow(r.window);
  view_->camera() = r.camera;
  again_.reset();
  return true;
}

}  // namespace tessera::session
