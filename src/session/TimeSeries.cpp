#include "tessera/session/TimeSeries.h"

#include <algorithm>
#include <string>

#include "tessera/core/Error.h"

namespace tessera::session {

TimeSeries::Reading TimeSeries::defaultReading() {
#if defined(__EMSCRIPTEN__) && !defined(__EMSCRIPTEN_PTHREADS__)
  return Reading::OnPump;
#else
  return Reading::Background;
#endif
}

TimeSeries::TimeSeries(int count, Reader read, int keep, Reading reading)
    : count_(count), read_(std::move(read)), keep_(keep), mode_(reading) {
  if (count_ < 1) throw InputError("time series: " + std::to_string(count_) + " time points");
  if (keep_ < 1 || keep_ > count_) {
    throw InputError("time series: keeping " + std::to_string(keep_) + " of " +
                     std::to_string(count_) + " time points, expected 1.." +
                     std::to_string(count_));
  }
  if (!read_) throw InputError("time series: no reader");
  if (mode_ == Reading::Background) worker_ = std::thread([this] { work(); });
}

TimeSeries::~TimeSeries() {
  if (!worker_.joinable()) return;
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  worker_.join();
}

int TimeSeries::keepWithin(std::uint64_t budgetBytes, std::uint64_t volumeBytes, int count) {
  const std::uint64_t fit = volumeBytes == 0 ? std::uint64_t(count) : budgetBytes / volumeBytes;
  return static_cast<int>(
      std::clamp<std::uint64_t>(fit, std::min(2, count), static_cast<std::uint64_t>(count)));
}

// Under mutex_: the window t .. t + keep - 1 (wrapping) is wanted, in that
// order; what is held outside it is let go, and so are failures outside it
// (a later visit tries again).
void TimeSeries::askFrom(int t) {
  if (t < 0 || t >= count_) {
    throw InputError("time point " + std::to_string(t) + " asked for, the series has " +
                     std::to_string(count_) + " (0.." + std::to_string(count_ - 1) + ")");
  }
  std::vector<int> window;
  for (int i = 0; i < keep_; ++i) window.push_back((t + i) % count_);
  std::erase_if(held_, [&](const auto& kv) { return !inWindow(kv.first, t); });
  std::erase_if(failed_, [&](const auto& kv) { return !inWindow(kv.first, t); });
  if (window != wanted_) {
    wanted_ = std::move(window);
    changed_.notify_all();
  }
}

std::shared_ptr<Volume> TimeSeries::want(int t) {
  std::lock_guard lock(mutex_);
  askFrom(t);
  const auto it = held_.find(t);
  return it == held_.end() ? nullptr : it->second;
}

std::shared_ptr<Volume> TimeSeries::wait(int t) {
  std::unique_lock lock(mutex_);
  askFrom(t);
  if (mode_ == Reading::OnPump && !held_.count(t) && !failed_.count(t)) {
    readOne(t, lock);
  }
  changed_.wait(lock, [&] { return held_.count(t) > 0 || failed_.count(t) > 0; });
  if (const auto f = failed_.find(t); f != failed_.end()) std::rethrow_exception(f->second);
  return held_.at(t);
}

std::vector<int> TimeSeries::readLog() const {
  std::lock_guard lock(mutex_);
  return readLog_;
}

int TimeSeries::nextToRead() const {
  for (const int t : wanted_) {
    if (!held_.count(t) && !failed_.count(t)) return t;
  }
  return -1;
}

void TimeSeries::readOne(int t, std::unique_lock<std::mutex>& lock) {
  reading_ = t;
  lock.unlock();
  std::shared_ptr<Volume> volume;
  std::exception_ptr error;
  try {
    volume = std::make_shared<Volume>(read_(t));
  } catch (...) {
    error = std::current_exception();
  }
  lock.lock();
  reading_ = -1;
  readLog_.push_back(t);
  // Kept only if still wanted (the viewer may have jumped elsewhere).
  if (std::find(wanted_.begin(), wanted_.end(), t) != wanted_.end()) {
    if (error) {
      failed_[t] = error;
    } else {
      held_[t] = std::move(volume);
    }
  }
  changed_.notify_all();
}

bool TimeSeries::isRead(int t) const {
  std::lock_guard lock(mutex_);
  return held_.count(t) > 0;
}

void TimeSeries::rethrowFailure(int t) const {
  std::exception_ptr failure;
  {
    std::lock_guard lock(mutex_);
    const auto f = failed_.find(t);
    if (f != failed_.end()) failure = f->second;
  }
  if (failure) std::rethrow_exception(failure);
}

bool TimeSeries::pump() {
  if (mode_ != Reading::OnPump) return false;
  std::unique_lock lock(mutex_);
  if (!arrived_) {
    const int next = nextToRead();
    if (next < 0) return false;
    readOne(next, lock);
    return true;
  }
  // In the order wanted: the first at hand is read; those before it are
  // asked for, up to `ahead` of them (a copy: the reader may not move the
  // window, but the list must not change under the loop).
  int asked = 0;
  for (const int t : std::vector<int>(wanted_)) {
    if (held_.count(t) || failed_.count(t)) continue;
    if (arrived_(t)) {
      readOne(t, lock);
      return true;
    }
    if (++asked >= ahead_) break;
  }
  return false;
}

void TimeSeries::setArrival(Arrival arrived, int ahead) {
  if (mode_ != Reading::OnPump) {
    throw InputError("time series: an arrival applies to a series read on pump()");
  }
  if (ahead < 1 || ahead > keep_) {
    throw InputError("time series: asking " + std::to_string(ahead) +
                     " time points ahead, expected 1.." + std::to_string(keep_));
  }
  std::lock_guard lock(mutex_);
  arrived_ = std::move(arrived);
  ahead_ = ahead;
}

void TimeSeries::work() {
  std::unique_lock lock(mutex_);
  for (;;) {
    int next = -1;
    changed_.wait(lock, [&] {
      if (stop_) return true;
      next = nextToRead();
      return next >= 0;
    });
    if (stop_) return;
    readOne(next, lock);
  }
}

Playback::Playback(double fps) : fps_(0.0) {
  setFps(fps);
}

void Playback::setFps(double fps) {
  if (!(fps >= 0.1 && fps <= 120.0)) {
    throw InputError("playback rate " + std::to_string(fps) +
                     " time points per second, expected 0.1..120");
  }
  fps_ = fps;
}

void Playback::play(double nowMs) {
  playing_ = true;
  dueMs_ = nowMs + 1000.0 / fps_;
}

int Playback::step(double nowMs, int shown, int count, bool nextReady) {
  if (!playing_ || count <= 1 || nowMs < dueMs_) return shown;
  if (!nextReady) {
    ++late_;
    return shown;
  }
  ++advances_;
  // On time (within a period of when it was due): the next is due a period
  // after this one was due, so frame jitter does not drift the rate. Late:
  // the clock starts again from now, so the rest are not hurried through.
  const double period = 1000.0 / fps_;
  const bool late = nowMs - dueMs_ > period;
  if (late) ++lateTimePoints_;
  dueMs_ = late ? nowMs + period : dueMs_ + period;
  return (shown + 1) % count;
}

}  // namespace tessera::session
