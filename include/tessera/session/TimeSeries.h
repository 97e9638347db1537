#pragma once
// Time series (a 4-D NIfTI such as an fMRI run; anything a reader gives one
// time point of at a time): the time points ahead of the one shown read in
// the background within a host budget, and playback at a chosen rate that
// shows every time point in order, a late one late, never skipping it.
//
//   TimeSeries series(20, [&](int t) { return readVolume(spec, {.time = t}); }, 4);
//   Playback play(10.0);                       // 10 time points per second
//   int shown = 0;
//   for (;;) {                                 // each frame of the viewer
//     shown = play.step(nowMs(), shown, series.count(), series.want(shown + 1) != nullptr);
//     draw(series.want(shown));
//   }
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "tessera/core/Volume.h"

namespace tessera::session {

class TimeSeries {
 public:
  using Reader = std::function<Volume(int time)>;
  // Whether time point `time`'s bytes are at hand, so that the reader
  // reads it without waiting; when they are not, it asks for them (a page
  // fetches them between its frames: an OME-Zarr store in the browser).
  using Arrival = std::function<bool(int time)>;
  // Where the time points ahead are read: on the series' own thread, or one
  // per pump() call on the caller's (a browser page without threads reads
  // between its frames).
  enum class Reading { Background, OnPump };
  // Background where the build has threads, OnPump in a WebAssembly build
  // without them.
  static Reading defaultReading();

  // `count` time points, each read by `read` (one at a time; with
  // Background on the series' own thread, so `read` must be callable from
  // there), at most `keep` of them held at once (1..count). InputError for
  // a count or keep out of range.
  TimeSeries(int count, Reader read, int keep, Reading reading = Reading::Background);
  ~TimeSeries();
  TimeSeries(const TimeSeries&) = delete;
  TimeSeries& operator=(const TimeSeries&) = delete;

  // How many time points fit `budgetBytes` when each takes `volumeBytes`:
  // at least 2 (the one shown and the next), at most `count`.
  static int keepWithin(std::uint64_t budgetBytes, std::uint64_t volumeBytes, int count);

  int count() const { return count_; }
  int keep() const { return keep_; }
  // Whether time point `x` is in the window want(t) keeps: t .. t + keep - 1,
  // wrapping past the last (for what a caller holds beside the series).
  bool inWindow(int x, int t) const { return (x - t + count_) % count_ < keep_; }

  // Time point `t` if it has been read, else null. Either way the reader
  // is asked for t and the keep - 1 time points after it (wrapping past the
  // last, as looped playback does), in that order; held time points outside
  // that window are let go. Thread-safe.
  std::shared_ptr<Volume> want(int t);
  // Waits until time point `t` is read (asking for it as want() does); the
  // reader's exception for it is rethrown. OnPump: reads it now.
  std::shared_ptr<Volume> wait(int t);
  // Whether time point `t` is read and held, without asking for anything
  // (want() moves the window of reads; this does not).
  bool isRead(int t) const;
  // Rethrows the reader's exception for time point `t` if its read failed
  // (and it is still in the window); else does nothing.
  void rethrowFailure(int t) const;
  // OnPump: reads the first wanted time point not read yet, if any, and
  // returns true when it read one. Background: does nothing, false.
  // With an arrival (setArrival): the first one at hand, asking for at
  // most `ahead` that are not, most urgent first.
  bool pump();
  // OnPump: time points are read only once `arrived` says their bytes are
  // at hand, and at most `ahead` (1..keep) not at hand are asked for at
  // once, so that what is fetched ahead fits what the fetcher keeps.
  // InputError for `ahead` out of range or a Background series.
  void setArrival(Arrival arrived, int ahead);
  Reading reading() const { return mode_; }
  // The time points read so far (a time point read again after it was let
  // go counts again): what a test checks the prefetch by.
  std::vector<int> readLog() const;

 private:
  void askFrom(int t);
  void work();
  // Under mutex_: the first wanted time point neither held nor failed, or -1.
  int nextToRead() const;
  // Reads `t` with mutex_ held by `lock` (released during the read) and
  // keeps it if it is still wanted.
  void readOne(int t, std::unique_lock<std::mutex>& lock);

  const int count_;
  const Reader read_;
  const int keep_;
  const Reading mode_;
  Arrival arrived_;
  int ahead_ = 0;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<int> wanted_;  // in the order to read
  std::map<int, std::shared_ptr<Volume>> held_;
  std::map<int, std::exception_ptr> failed_;
  std::vector<int> readLog_;
  int reading_ = -1;
  bool stop_ = false;
  std::thread worker_;
};

// The clock of playback at `fps` time points per second. step() is called
// once per drawn frame; it moves to the next time point when that one is
// due and read. A due time point that is not read yet holds the one shown
// (counted as a late frame) until it is: every time point is shown, in
// order, wrapping after the last.
class Playback {
 public:
  explicit Playback(double fps = 10.0);

  double fps() const { return fps_; }
  void setFps(double fps);  // InputError unless 0.1..120
  bool playing() const { return playing_; }
  void play(double nowMs);
  void pause() { playing_ = false; }

  // The time point to show at `nowMs`, given the one shown now and whether
  // the next one (shown + 1, wrapping) has been read.
  int step(double nowMs, int shown, int count, bool nextReady);

  // Frames where a due time point was not read yet, and time points shown.
  std::uint64_t lateFrames() const { return late_; }
  std::uint64_t advances() const { return advances_; }
  // Time points shown late: more than a period after they were due (the
  // clock then starts again from when it was shown).
  std::uint64_t lateTimePoints() const { return lateTimePoints_; }

 private:
  double fps_;
  bool playing_ = false;
  double dueMs_ = 0.0;
  std::uint64_t late_ = 0;
  std::uint64_t advances_ = 0;
  std::uint64_t lateTimePoints_ = 0;
};

}  // namespace tessera::session
