#pragma once
// The channels of a store with a t axis played back together
// (session/ChannelView.h): each time point's channels are read as one set
// (io/ZarrChannels.h, that time point's chunks of every channel) and read
// ahead as a TimeSeries reads single volumes (its window, thread or pump,
// late-never-skipped playback); a time point is shown when all of its
// channels are read, never some channels of one and some of another.
//
//   ChannelSeries s(store.timePoints(), [&](int t) { return readZarrChannels(spec, {}, t); }, 3);
//   if (auto set = s.want(t)) show(*set);
#include <functional>
#include <map>
#include <memory>
#include <mutex>

#include "tessera/core/ChannelSet.h"
#include "tessera/session/TimeSeries.h"

namespace tessera::session {

class ChannelSeries {
 public:
  using Reader = std::function<ChannelSet(int time)>;

  // `count` time points read by `read`, at most `keep` (1..count) held.
  // InputError as TimeSeries.
  ChannelSeries(int count, Reader read, int keep,
                TimeSeries::Reading reading = TimeSeries::defaultReading());

  // The read-ahead (a time point is read when its whole set is; the volume
  // it holds is the first channel's shape, no voxels).
  TimeSeries& series() { return *series_; }
  int count() const { return series_->count(); }
  // Time point t's channels when read, else null; asks as TimeSeries::want
  // and lets go of the sets outside the window.
  std::shared_ptr<const ChannelSet> want(int t);
  // The bytes of a set's voxels (what keepWithin weighs).
  static std::uint64_t bytes(const ChannelSet& set);

 private:
  Volume read(int t);

  Reader read_;
  std::mutex mutex_;
  std::map<int, std::shared_ptr<const ChannelSet>> sets_;
  std::unique_ptr<TimeSeries> series_;  // last: its thread stops first
};

}  // namespace tessera::session
