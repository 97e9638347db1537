#include "tessera/session/ChannelSeries.h"

#include "tessera/core/Error.h"

namespace tessera::session {

ChannelSeries::ChannelSeries(int count, Reader read, int keep, TimeSeries::Reading reading)
    : read_(std::move(read)) {
  if (!read_) throw InputError("channel series: no reader");
  series_ = std::make_unique<TimeSeries>(
      count, [this](int t) { return this->read(t); }, keep, reading);
}

std::uint64_t ChannelSeries::bytes(const ChannelSet& set) {
  std::uint64_t sum = 0;
  for (const Channel& c : set.channels()) sum += c.volume ? c.volume->byteSize() : 0;
  return sum;
}

// On the series' thread (or its pump): the whole set, kept beside the
// series; the series holds only its shape.
Volume ChannelSeries::read(int t) {
  auto set = std::make_shared<const ChannelSet>(read_(t));
  if (set->empty()) throw InputError("time point " + std::to_string(t) + ": no channels read");
  const Volume& first = set->geometry();
  Volume shape = Volume::shapeOnly(first.dims(), first.type());
  std::lock_guard lock(mutex_);
  sets_[t] = std::move(set);
  return shape;
}

std::shared_ptr<const ChannelSet> ChannelSeries::want(int t) {
  const bool read = series_->want(t) != nullptr;
  std::lock_guard lock(mutex_);
  std::erase_if(sets_, [&](const auto& kv) { return !series_->inWindow(kv.first, t); });
  if (!read) return nullptr;
  const auto it = sets_.find(t);
  return it == sets_.end() ? nullptr : it->second;
}

}  // namespace tessera::session
