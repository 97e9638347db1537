#pragma once
// The 3D view's frames of a streamed volume in an interactive front end:
// the session's pyramid (a store's time point played over bricks,
// session/StreamedSeries.h) drawn through a bricks layout and refined a
// step per front-end frame (session/BrickRefinement.h), at the session's
// current settings (the view's camera, transfer function, window and render
// settings). A new time point of the same store (the same levels, bricks
// and stored precision) is streamed into the layout already on the GPU
// (StreamingLayout::replaceSources): the last one's bricks let go, its
// coarsest level pinned in the same slots and its finer bricks streamed
// into the same atlas, so that no texture is made and no shader compiled
// between time points, and no brick of another time point is drawn. A
// pyramid of another grid, or other settings, gets a layout of its own,
// made after the last one's textures are let go: one atlas on the GPU at
// a time. With the channel view's channels over bricks
// (ChannelView::overBricks, Session::streamChannels) it draws them
// together, as Session::renderChannels does: one bricks layout over every
// channel's pyramid of the time point (BricksLayout::createChannels), each
// time point streamed into it the same way, with the channel view's
// colours, windows and visibility.
// Session::stepPlayback moves on only once the time point shown has been
// drawn complete (every brick its view wants resident): every time point
// is shown refined, none skipped.
//
//   session.openInView("series.ome.zarr");     // a t axis over bricks
//   const gpu::Texture& frame = session.streamedFrames().render(512, 512);
//   if (session.streamedFrames().complete()) ...  // refined: playback may move on
#include <cstdint>
#include <memory>
#include <string>

#include "tessera/core/Image.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/layout/StreamingLayout.h"
#include "tessera/lod/MultiresSource.h"
#include "tessera/session/BrickRefinement.h"
#include "tessera/session/Settings.h"

namespace tessera::session {

class Session;

class StreamedFrames {
 public:
  explicit StreamedFrames(Session& session);
  ~StreamedFrames();
  StreamedFrames(const StreamedFrames&) = delete;
  StreamedFrames& operator=(const StreamedFrames&) = delete;

  // How long one render() may stream (read and upload bricks) before it
  // draws: the front end answers input between frames.
  StreamPace pace{.streamMs = 100.0, .idleWaitMs = 10.0};
  // false: a layout of its own for every time point, as before the atlas
  // was kept (`tessera bench --playback` compares the two).
  bool reuseLayout = true;

  // One step for the view: the bricks it wants selected, the arrived ones
  // uploaded (within `pace`), and the frame drawn. Drawn again only while it
  // refines or when the pyramid (another time point), the settings or the
  // size changed; row 0 at the bottom, valid until the next call. InputError
  // when the session has no streamed volume or its technique does not
  // stream bricks.
  const gpu::Texture& render(int width, int height);
  // Whether the last frame drew every brick its view wants (resident, or
  // given up after its reads kept failing), and of which time point.
  bool complete() const { return complete_; }
  int timePoint() const { return timePoint_; }
  // Whether time point `t`'s frame has been drawn complete at the current
  // pyramid: what playback waits for before it moves on.
  bool shownComplete(int t) const;
  // The last step's bricks (wanted, missing, levels), the layouts made so
  // far (one per store and settings shown) and the time points streamed
  // into a layout made for an earlier one.
  const layout::BricksFrame& lastBricks() const { return last_; }
  int layoutsMade() const { return layoutsMade_; }
  int timePointsStreamedIn() const { return timePointsStreamedIn_; }
  // The last frame, top row first.
  Image readImage() const;
  // Lets the GPU objects go (another volume replaced the streamed one).
  void close();

 private:
  struct Gpu;
  void makeLayout(const std::shared_ptr<const lod::MultiresSource>& pyramid, const Settings& s,
                  int width, int height, ValueRange window, const std::string& key);
  void streamInto(const std::shared_ptr<const lod::MultiresSource>& pyramid, ValueRange window);
  bool drawsChannels() const;

  Session& session_;
  std::unique_ptr<Gpu> gpu_;
  layout::BricksFrame last_;
  bool complete_ = false;
  int timePoint_ = -1;
  int layoutsMade_ = 0;
  int timePointsStreamedIn_ = 0;
};

}  // namespace tessera::session
