#pragma once
// A streamed store's t axis played over bricks (layout/BricksLayout.h):
// each time point is a pyramid of its own, read from that time point's
// chunks only (lod::ZarrMultiresSource::atTime), and a frame of time point t
// is drawn by a bricks layout streaming t's pyramid alone (made for it, or
// made for an earlier time point and t streamed into it:
// StreamingLayout::replaceSources), so its brick cache and atlas hold t's
// bricks alone: no brick of another time point is drawn for it. The time
// points ahead of the one shown are read ahead as a TimeSeries reads
// in-core ones (its window, thread or pump, late-never-skipped playback):
// each is opened and its levels, coarsest first, read into its
// decoded-chunk cache while they fit `warmBytes`, so that when playback
// moves on, the next time point's bricks come from memory.
//
//   StreamedSeries s(store.timePoints(), [&](int t) { return store.atTime(t); },
//                    hostBudget / 8, 2);
//   s.series().want(0);                       // time points 0 and 1 warmed
//   draw(*s.source(0));                       // a bricks layout over time point 0
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

#include "tessera/lod/MultiresSource.h"
#include "tessera/session/TimeSeries.h"

namespace tessera::session {

class StreamedSeries {
 public:
  using SourceAt = std::function<std::shared_ptr<const lod::MultiresSource>(int time)>;
  using Pyramids = std::vector<std::shared_ptr<const lod::MultiresSource>>;
  using SourcesAt = std::function<Pyramids(int time)>;

  // `count` time points, each opened by `at` (from the series' thread when
  // `reading` is Background), `keep` (2..count) warmed at once, each warmed
  // up to `warmBytes` of its levels. InputError as TimeSeries.
  StreamedSeries(int count, SourceAt at, std::uint64_t warmBytes, int keep,
                 TimeSeries::Reading reading = TimeSeries::defaultReading());
  // Several channels: `at` opens every channel's pyramid of a time point
  // (the same number each time, the same levels).
  StreamedSeries(int count, SourcesAt at, std::uint64_t warmBytes, int keep,
                 TimeSeries::Reading reading = TimeSeries::defaultReading());

  // The read-ahead: a time point is "read" once its pyramid is opened and
  // warmed; the volume it holds is that pyramid's coarsest level.
  TimeSeries& series() { return *series_; }
  const TimeSeries& series() const { return *series_; }
  int count() const { return series_->count(); }

  // Time point t's pyramid: the one warmed ahead, or opened now. Pyramids
  // outside the series' window (t and the keep - 1 after it) are let go.
  std::shared_ptr<const lod::MultiresSource> source(int t);
  // Every channel's pyramid of time point t (one without channels).
  Pyramids sources(int t);
  // Time point t's pyramid if it is open (read ahead or shown), else null;
  // unlike source(), the window stays where it is.
  std::shared_ptr<const lod::MultiresSource> held(int t) const;

  // The levels, coarsest first, whose voxels fit `bytes` together (at least
  // the coarsest): what warming a time point reads.
  static std::vector<int> levelsWithin(const lod::MultiresSource& source, std::uint64_t bytes);
  // Per time point warmed, in the order warmed: the levels read (of the
  // first channel).
  std::vector<std::vector<int>> warmedLevels() const;

 private:
  Volume warm(int t);
  Pyramids opened(int t);

  SourcesAt at_;
  std::uint64_t warmBytes_;
  mutable std::mutex mutex_;
  std::map<int, Pyramids> sources_;
  std::vector<std::vector<int>> warmed_;
  std::unique_ptr<TimeSeries> series_;  // last: its thread stops first
};

}  // namespace tessera::session
