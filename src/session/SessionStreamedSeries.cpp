// Session's streamed time series (session/StreamedSeries.h): a store's t
// axis played over bricks. Each time point shown is its own pyramid, so the
// bricks layout that the next frame (run(), render()) makes over it holds
// that time point's bricks only.
#include <algorithm>

#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/io/ZarrChannels.h"
#include "tessera/lod/MultiresVolumeSource.h"
#include "tessera/lod/WindowedSource.h"
#include "tessera/lod/ZarrMultiresSource.h"
#include "tessera/session/Session.h"
#include "tessera/viewer/Explorer.h"

namespace tessera::session {

#ifndef __EMSCRIPTEN__
// Native only: the page fetches its stores itself (ZarrStoreView).
void Session::openStreamedSeries(const std::string& spec, const OpenOptions& options) {
  settings_.validate();
  std::shared_ptr<const lod::ZarrMultiresSource> first =
      lod::ZarrMultiresSource::open(spec, {.time = options.time, .channel = options.channel});
  const int count = first->store().timePoints();
  if (count < 2) {
    throw InputError(spec + ": one time point, not a time series (a store with a t axis is)");
  }
  // Each time point keeps its decoded chunks within the store's share of
  // the host budget (ZarrMultiresSource::decodedChunkBudget) and warms as
  // much: as many time points ahead as a quarter of the budget holds.
  const std::uint64_t host = HostBudget::global().limitBytes();
  const std::uint64_t each = lod::ZarrMultiresSource::decodedChunkBudget(first->store(), host);
  const int keep = TimeSeries::keepWithin(host / 4, each, count);
  const int firstTime = options.time;
  auto series = std::make_unique<StreamedSeries>(
      count,
      [first, firstTime](int t) -> std::shared_ptr<const lod::MultiresSource> {
        if (t == firstTime) return first;
        return first->atTime(t);
      },
      each, keep);
  inCore_.reset();
  resident_.reset();
  region_.reset();
  series_.reset();
  exploration_.reset();
  // Every time point in the first one's window, unless the settings say one.
  seriesWindow_ = settings_.window ? *settings_.window : first->shape().window();
  streamedSeries_ = std::move(series);
  streamedChannels_.clear();
  seriesDrawn_ = false;
  name_ = spec;
  timePoint_ = -1;
  if (!showStreamedTimePoint(firstTime))
    throw Error(spec + ": its first time point was not opened");
}

ChannelSet Session::streamChannels(const std::vector<int>& indices) {
  if (!streamedSeries_ || seriesDrawn_ || !streamed_) {
    throw InputError("no store is played over bricks: its channels cannot stream together");
  }
  const std::string spec = name_;
  const int time = timePoint_;
  const int count = streamedSeries_->count();
  std::vector<std::shared_ptr<const lod::ZarrMultiresSource>> firsts;
  ChannelSet set;
  {
    const auto store = lod::ZarrMultiresSource::open(spec, {.time = time, .channel = 0});
    for (int c : zarrChannelIndices(store->store(), spec, indices)) {
      firsts.push_back(lod::ZarrMultiresSource::open(spec, {.time = time, .channel = c}));
      const lod::ZarrMultiresSource& f = *firsts.back();
      set.add(zarrChannel(f.store(), c, Volume(f.shape())), spec + " channel " + std::to_string(c));
    }
  }
  if (set.size() < 2) return set;
  // As openStreamedSeries, the budget shared by the channels: each time
  // point's decoded chunks of every channel, as many ahead as a quarter of
  // the host budget holds.
  const std::uint64_t host = HostBudget::global().limitBytes();
  std::uint64_t each = 0;
  for (const auto& f : firsts) {
    each += lod::ZarrMultiresSource::decodedChunkBudget(f->store(), host);
  }
  const int keep = TimeSeries::keepWithin(host / 4, each, count);
  streamedSeries_ = std::make_unique<StreamedSeries>(
      count,
      [firsts, time](int t) {
        StreamedSeries::Pyramids out;
        for (const auto& f : firsts) {
          out.push_back(t == time ? std::shared_ptr<const lod::MultiresSource>(f) : f->atTime(t));
        }
        return out;
      },
      each, keep);
  timePoint_ = -1;
  if (!showStreamedTimePoint(time)) throw Error(spec + ": its channels were not opened");
  return set;
}

// The view holds the time point's coarsest level, read with it ahead (its
// histogram, window and camera; the exploration's overview); its frames
// are the front end's streamedFrames(). The view's look carries over.
void Session::openStreamedSeriesInView(const std::string& spec, const OpenOptions& options) {
  viewer::Viewer& v = view();
  const Settings before = settings_;
  settings_ = currentSettings();
  settings_.window.reset();  // the series' own
  try {
    openStreamedSeries(spec, options);
  } catch (...) {
    settings_ = before;
    throw;
  }
  if (streamedFrames_) streamedFrames_->close();
  closeChannelView();
  Exploration& e = exploration();
  v.setVolume(Volume(*e.overview()), e.overviewName());
  v.setWindow(*seriesWindow_);
  const bool tfChanged = applyModalityDefault(v.volume());
  showDefaultInView(tfChanged);
}
#endif

void Session::drawStreamedSeries(int count, StreamedSeries::SourceAt at, std::uint64_t warmBytes,
                                 std::uint64_t heldBytes, const std::string& name, int time,
                                 TimeSeries::Reading reading) {
  if (count < 2) throw InputError(name + ": one time point, not a time series");
  if (time < 0 || time >= count) {
    throw InputError(name + ": time point " + std::to_string(time) + " asked for, the series has " +
                     std::to_string(count) + " (0.." + std::to_string(count - 1) + ")");
  }
  const int keep = TimeSeries::keepWithin(heldBytes, std::max<std::uint64_t>(1, warmBytes), count);
  auto series = std::make_unique<StreamedSeries>(count, std::move(at), warmBytes, keep, reading);
  // The first time point is shown now (the front end draws it already);
  // it and the ones after it are read ahead from here.
  std::shared_ptr<const lod::MultiresSource> first = series->source(time);
  series_.reset();
  streamedSeries_ = std::move(series);
  seriesDrawn_ = true;
  drawn_ = std::move(first);
  timePoint_ = time;
}

void Session::drawPyramid(std::shared_ptr<const lod::MultiresSource> pyramid) {
  if (seriesDrawn_ && streamedSeries_) {
    streamedSeries_.reset();
    timePoint_ = 0;
  }
  seriesDrawn_ = false;
  drawn_ = std::move(pyramid);
}

// The front end's reads never wait: a time point is shown once it is read
// (its pyramid opened and its levels at hand), a jump too, and a region or
// grid block in the view once its level-0 chunks of that time point have
// arrived; until then the one shown stays. The exploration of the drawn
// pyramid follows (its crosshair, region side, picked box and grid), and
// the region or block in the view is read again from the new time point,
// the camera and window staying where the user left them.
bool Session::showDrawnTimePoint(int t) {
  const bool read = streamedSeries_->series().want(t) != nullptr;  // checks t
  if (t == timePoint_) return true;
  if (!read) return false;
  std::shared_ptr<const lod::MultiresSource> next = streamedSeries_->source(t);
  const std::optional<lod::VoxelBox> box = drawnBoxInView();
  if (box && !next->prefetch(0, *box)) return false;
  const bool explored = exploration_ && &exploration_->explorer().source() == drawn_.get();
  drawn_ = std::move(next);
  timePoint_ = t;
  if (!explored) return true;
  const nlohmann::json state = exploration_->state();
  const std::string label = exploration_->label();
  // A region to show again after a lost context (again_) is shown from
  // this time point's pyramid too (showRegionAgain reads the exploration's).
  exploration_ =
      std::make_unique<Exploration>(drawn_, viewer::regionBudgetBytes(device_.limits), 0, label);
  if (box) {
    showExplorationAgain(state);
  } else {
    exploration_->restore(state);
  }
  return true;
}

std::optional<lod::VoxelBox> Session::boxInView() const {
  const Exploration* e = exploration_.get();
  if (!e || e->mode() == ExploreMode::Overview || !e->shown() || !view_ || !view_->hasVolume() ||
      view_->volumeName() != e->shownName()) {
    return std::nullopt;
  }
  return e->shown();
}

std::optional<lod::VoxelBox> Session::drawnBoxInView() const {
  const Exploration* e = exploration_.get();
  if (!drawn_ || !e || &e->explorer().source() != drawn_.get()) return std::nullopt;
  return boxInView();
}

bool Session::drawnBoxArrived(int t) const {
  if (!seriesDrawn_ || !streamedSeries_) return true;
  const std::optional<lod::VoxelBox> box = drawnBoxInView();
  if (!box) return true;
  // Read ahead, so held; one that is not is opened when shown
  // (showDrawnTimePoint checks the box again then).
  const std::shared_ptr<const lod::MultiresSource> next = streamedSeries_->held(t);
  return !next || next->prefetch(0, *box);
}

Exploration& Session::exploreDrawn(const std::string& label) {
  makeCurrent();
  // Read in core (a store whose level 0 fits, its time points read by
  // openSeries): the time point's level 0 is the session's volume, which
  // showTimePoint carries the exploration over to. (Another series left in
  // the session, a dropped file's, has another grid than the drawn one.)
  if (series_ && inCore_ && (!drawn_ || inCore_->volume().dims() == drawn_->levelInfo(0).dims)) {
    exploration_ = std::make_unique<Exploration>(inCore_->level(glm::ivec3(1)),
                                                 viewer::regionBudgetBytes(device_.limits), label);
    return *exploration_;
  }
  if (!drawn_) throw InputError("exploring: no pyramid is drawn");
  return explore(drawn_, 0, label);
}

std::uint64_t Session::explorationOverviewVoxels() const {
  // A series over bricks: the coarsest level, warmed ahead with each time
  // point, rather than a finer one read again at every time point.
  if (streamedSeries_ && streamed_) {
    const glm::ivec3 d = streamed_->levelInfo(streamed_->levelCount() - 1).dims;
    return static_cast<std::uint64_t>(d.x) * static_cast<std::uint64_t>(d.y) *
           static_cast<std::uint64_t>(d.z);
  }
  return viewer::overviewVoxelBudget(device_.limits);
}

const StreamedSeries::Pyramids& Session::streamedChannels() const {
  static const StreamedSeries::Pyramids none;
  return streamedSeries_ && !seriesDrawn_ ? streamedChannels_ : none;
}

TimeSeries* Session::series() {
  if (channelView_ && channelView_->series()) return &channelView_->series()->series();
  if (series_) return series_.get();
  return streamedSeries_ ? &streamedSeries_->series() : nullptr;
}

int Session::timePoint() const {
  if (channelView_ && channelView_->series()) return channelView_->timePoint();
  return timePoint_;
}

bool Session::showStreamedTimePoint(int t) {
  if (seriesDrawn_) return showDrawnTimePoint(t);
  if (t == timePoint_ && streamed_) return true;
  // The shown one is opened now if it has to be (a jump); playback asks
  // only for one warmed ahead (stepPlayback waits for isRead).
  StreamedSeries::Pyramids all = streamedSeries_->sources(t);
  // The exploration carries over (its crosshair, region side, picked box
  // and grid), and a region or grid block in the view is read again from
  // time point t, the camera and window staying where the user left them.
  std::optional<nlohmann::json> explored;
  if (exploration_) explored = exploration_->state();
  std::shared_ptr<const lod::MultiresSource> source = all.front();
  if (all.size() > 1) {
    streamedChannels_ = std::move(all);
  } else {
    streamedChannels_.clear();
  }
  if (!settings_.window && seriesWindow_) {
    source = std::make_shared<lod::WindowedSource>(std::move(source), *seriesWindow_);
  }
  streamed_ = std::move(source);
  exploration_.reset();
  timePoint_ = t;
  applyVolumeSettings();  // streamedView_: this time point, through the settings' window
  if (explored) showExplorationAgain(*explored);
  return true;
}

}  // namespace tessera::session
