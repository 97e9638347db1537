#include "tessera/session/StreamedSeries.h"

#include <algorithm>
#include <optional>

#include "tessera/core/Error.h"
#include "tessera/lod/ReadLevel.h"

namespace tessera::session {

StreamedSeries::StreamedSeries(int count, SourceAt at, std::uint64_t warmBytes, int keep,
                               TimeSeries::Reading reading)
    : StreamedSeries(
          count,
          at ? SourcesAt([at = std::move(at)](int t) { return Pyramids{at(t)}; }) : SourcesAt(),
          warmBytes, keep, reading) {}

StreamedSeries::StreamedSeries(int count, SourcesAt at, std::uint64_t warmBytes, int keep,
                               TimeSeries::Reading reading)
    : at_(std::move(at)), warmBytes_(warmBytes) {
  if (!at_) throw InputError("streamed series: no source per time point");
  series_ = std::make_unique<TimeSeries>(
      count, [this](int t) { return warm(t); }, keep, reading);
}

std::vector<int> StreamedSeries::levelsWithin(const lod::MultiresSource& source,
                                              std::uint64_t bytes) {
  std::vector<int> levels;
  std::uint64_t sum = 0;
  for (int l = source.levelCount() - 1; l >= 0; --l) {
    sum += lod::levelBytes(source, l);
    if (sum > bytes && !levels.empty()) break;
    levels.push_back(l);
  }
  return levels;
}

StreamedSeries::Pyramids StreamedSeries::opened(int t) {
  {
    std::lock_guard lock(mutex_);
    const auto it = sources_.find(t);
    if (it != sources_.end()) return it->second;
  }
  // Opened outside the lock (a store reads its metadata); a second opener
  // of the same time point keeps the first one's.
  Pyramids sources = at_(t);
  if (sources.empty() || std::find(sources.begin(), sources.end(), nullptr) != sources.end()) {
    throw InputError("streamed series: no pyramid for time point " + std::to_string(t));
  }
  std::lock_guard lock(mutex_);
  return sources_.emplace(t, std::move(sources)).first->second;
}

// On the series' thread (or its pump): the pyramid opened, and its levels
// that fit warmBytes_ read, coarsest first, into its decoded-chunk cache.
Volume StreamedSeries::warm(int t) {
  const Pyramids sources = opened(t);
  std::optional<Volume> coarsest;
  std::vector<int> first;
  for (const auto& source : sources) {
    const std::vector<int> levels = levelsWithin(*source, warmBytes_ / sources.size());
    Volume top = lod::readLevel(*source, levels.front());
    for (std::size_t i = 1; i < levels.size(); ++i) (void)lod::readLevel(*source, levels[i]);
    if (!coarsest) {
      coarsest = std::move(top);
      first = levels;
    }
  }
  std::lock_guard lock(mutex_);
  warmed_.push_back(first);
  return std::move(*coarsest);
}

StreamedSeries::Pyramids StreamedSeries::sources(int t) {
  series_->want(t);  // moves the window (and checks t)
  {
    std::lock_guard lock(mutex_);
    std::erase_if(sources_, [&](const auto& kv) { return !series_->inWindow(kv.first, t); });
  }
  return opened(t);
}

std::shared_ptr<const lod::MultiresSource> StreamedSeries::source(int t) {
  return sources(t).front();
}

std::shared_ptr<const lod::MultiresSource> StreamedSeries::held(int t) const {
  std::lock_guard lock(mutex_);
  const auto it = sources_.find(t);
  return it == sources_.end() ? nullptr : it->second.front();
}

std::vector<std::vector<int>> StreamedSeries::warmedLevels() const {
  std::lock_guard lock(mutex_);
  return warmed_;
}

}  // namespace tessera::session
