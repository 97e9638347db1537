#pragma once
// The channels of a store shown together in the interactive front ends
// (docs/channels.md): the desktop viewer's and the page's channel lists
// only call these (a colour, a window, a visibility toggle per channel and
// the mode) and show render()'s frame in the 3D view. The state is the
// session's settings().channels, so that state()/restore() keep it; the
// channels' voxels are uploaded once (layout::ChannelLayout) and an edit
// changes uniforms only.
//
//   session.channelView().open("cells.ome.zarr");
//   session.channelView().setVisible(1, false);
//   const gpu::Texture& frame = session.channelView().render(512, 512);
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "tessera/core/ChannelSet.h"
#include "tessera/core/Image.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/session/ChannelSeries.h"

namespace tessera::session {

class Session;

class ChannelView {
 public:
  explicit ChannelView(Session& session);
  ~ChannelView();
  ChannelView(const ChannelView&) = delete;
  ChannelView& operator=(const ChannelView&) = delete;

  // Reads the channels of the OME-Zarr store `spec` (settings().channels'
  // indices, colours, windows and visibility over the store's omero
  // defaults) and shows them; false, with nothing changed, when `spec` is
  // not a store or has one channel. InputError as readZarrChannels.
  // The store the session plays over bricks (Session::openStreamedSeries,
  // `view --bricks`) is not read in core: its channels stream together
  // (Session::streamChannels) at the session's time point, and the frame is
  // the session's streamedFrames() (overBricks()).
  bool open(const std::string& spec, int time = 0);
  // Whether the channels shown are the session's streamed ones.
  bool overBricks() const { return overBricks_; }
  // A store with a t axis: open() shows time point `time` and reads the
  // ones after it ahead (session/ChannelSeries.h), so that its channels play
  // together through Session::stepPlayback; null otherwise.
  ChannelSeries* series() { return series_.get(); }
  int timePoint() const;
  // Shows time point t's channels when they are read (the colours, windows
  // and visibility stay: they are the settings'), else asks for them and
  // returns false. InputError without a series or for t out of range.
  bool showTime(int t);
  // A store's t axis whose channels the caller reads (the page's store
  // over fetch()): `first`, time point `time`'s set, shown now under
  // `name` with settings().channels applied, and the time points after it
  // read ahead by `read` as `reading` says, as many held as a quarter of
  // the host budget holds. With `arrived` (an OnPump series), a time point
  // is read once its bytes are at hand, at most `ahead` asked for at once
  // (TimeSeries::setArrival). open() plays a store's t axis through this.
  // InputError for fewer than 2 time points or `time` out of range.
  void showSeries(int count, ChannelSet first, ChannelSeries::Reader read, const std::string& name,
                  int time, TimeSeries::Reading reading = TimeSeries::defaultReading(),
                  TimeSeries::Arrival arrived = {}, int ahead = 1);
  // Channels the caller read (the page's store over fetch()), shown under
  // `name` with settings().channels applied.
  void show(ChannelSet set, const std::string& name);
  // Back to the session's volume alone (settings().channels disabled).
  void close();
  bool isOpen() const { return set_ != nullptr; }
  // The channels shown (with their colours, windows, visibility and mode)
  // and their name, taken out of the view, which closes. For a session made
  // again on a restored GPU context (a phone's browser took WebGL away): its
  // view's show() draws the same frame, the voxels kept in memory, not read
  // again. Null when none are shown.
  struct Shown {
    ChannelSet set;
    std::string name;
  };
  std::optional<Shown> takeShown();
  const std::string& name() const { return name_; }
  // The channels shown, with their current colour, window and visibility.
  const ChannelSet& channels() const;

  // One channel's colour (linear RGB in [0,1]), window (stored units,
  // lo < hi) or visibility; InputError for an index out of range or a
  // value settings validation refuses. Each edit goes to settings().channels.
  void setColor(int i, glm::dvec3 rgb);
  void setWindow(int i, ValueRange window);
  void setVisible(int i, bool visible);
  void setMode(ChannelMode mode);
  // Counts the edits (a front end redraws its list when it changes).
  std::uint64_t revision() const { return revision_; }

  // The channels' frame at the session's current settings (the view's
  // camera, transfer function and render settings when it has a view),
  // rendered again only when one of them, an edit or the size changed. Row 0
  // at the bottom; valid until the next call.
  const gpu::Texture& render(int width, int height);
  // The last frame, top row first.
  Image readImage() const;
  // Draws the last frame (in core; over bricks the front end draws
  // streamedFrames()'s) into `framebuffer`'s box (x, y, width, height; 0:
  // the window or canvas), scaled to it (the page's canvas).
  void present(unsigned framebuffer, glm::ivec4 box);

 private:
  struct Gpu;
  void requireOpen(int i) const;
  void showOverBricks(ChannelSet set, const std::string& name);
  void edited();

  Session& session_;
  std::string name_;
  std::unique_ptr<ChannelSet> set_;  // the layout reads it at every frame
  std::unique_ptr<Gpu> gpu_;
  std::unique_ptr<ChannelSeries> series_;
  int time_ = 0;
  bool overBricks_ = false;
  std::uint64_t revision_ = 0;
  std::string frameKey_;
};

}  // namespace tessera::session
