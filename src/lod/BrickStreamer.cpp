#include "tessera/lod/BrickStreamer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <exception>
#include <system_error>

#include "tessera/core/Error.h"

namespace tessera::lod {

BrickStreamer::BrickStreamer(std::shared_ptr<const MultiresSource> source, BrickGrid grid,
                             BrickStreamerOptions options)
    : source_(std::move(source)),
      grid_(std::move(grid)),
      mapping_(StoredMapping::of(source_->shape())),
      options_(options) {
  for (int l = 0; l < grid_.levelCount(); ++l) chunks_.push_back(source_->levelInfo(l).chunk);
  // Without threads (workers = 0, or a platform that cannot start them, such
  // as the browser build) request() reads a few bricks itself.
  try {
    for (int i = 0; i < options_.workers; ++i) workers_.emplace_back([this] { work(); });
  } catch (const std::system_error&) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : workers_) t.join();
    workers_.clear();
    stop_ = false;
  }
}

BrickStreamer::~BrickStreamer() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    queue_.clear();
  }
  wake_.notify_all();
  for (std::thread& t : workers_) t.join();
}

double BrickStreamer::nowMs() const {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

void BrickStreamer::request(const std::vector<BrickKey>& keys) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.clear();
    const double now = nowMs();
    std::unordered_set<std::uint64_t> queued;
    // Bricks whose reads failed go after every brick not tried yet: a few
    // failing bricks near the eye, each as slow to fail as the source's own
    // retries, would otherwise keep the readers busy and the rest unread.
    std::vector<BrickKey> fresh;
    std::vector<BrickKey> retries;
    for (const BrickKey& k : keys) {
      const std::uint64_t id = k.id();
      if (cached_.count(id) || reading_.count(id) || !queued.insert(id).second) continue;
      const auto f = failures_.find(id);
      if (f == failures_.end()) {
        fresh.push_back(k);
      } else if (f->second.retryAtMs <= now && !givenUp(id)) {
        retries.push_back(k);
      }
    }
    fresh = groupedByChunk(std::move(fresh));
    queue_.assign(fresh.begin(), fresh.end());
    queue_.insert(queue_.end(), retries.begin(), retries.end());
  }
  wake_.notify_all();
  if (workers_.empty()) readQueuedInline(options_.inlineReadsPerRequest);
}

std::vector<BrickKey> BrickStreamer::groupedByChunk(std::vector<BrickKey> keys) const {
  // The chunk holding the brick's centre; its apron may reach into the
  // neighbours, which the source's chunk cache keeps meanwhile.
  const auto chunkOf = [&](const BrickKey& k) {
    const glm::ivec3 chunk = chunks_[std::size_t(k.level)];
    const VoxelBox box = grid_.readBox(k);
    const glm::ivec3 c = (box.begin + box.end) / 2 / chunk;
    return std::array<int, 4>{k.level, c.z, c.y, c.x};
  };
  std::map<std::array<int, 4>, std::size_t> groupOf;
  std::vector<std::vector<BrickKey>> groups;
  for (const BrickKey& k : keys) {
    if (std::size_t(k.level) >= chunks_.size() ||
        glm::any(glm::lessThanEqual(chunks_[std::size_t(k.level)], glm::ivec3(0)))) {
      return keys;  // the source reads no chunks: keep the order
    }
    const auto [it, added] = groupOf.try_emplace(chunkOf(k), groups.size());
    if (added) groups.emplace_back();
    groups[it->second].push_back(k);
  }
  keys.clear();
  for (const std::vector<BrickKey>& g : groups) keys.insert(keys.end(), g.begin(), g.end());
  return keys;
}

void BrickStreamer::readQueuedInline(int count) {
  int notReady = 0;
  while (count > 0) {
    BrickKey key;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (queue_.empty()) return;
      key = queue_.front();
      queue_.pop_front();
    }
    // A brick whose bytes are still on their way is asked for again next
    // request; waiting here would block the (browser's only) thread.
    if (!source_->prefetch(key.level, grid_.readBox(key))) {
      if (++notReady >= options_.prefetchAhead) return;
      continue;
    }
    --count;
    try {
      readNow(key);
    } catch (const std::exception&) {
      // recorded by readNow; the brick is retried after its back-off
    }
  }
}

std::shared_ptr<const StoredBrick> BrickStreamer::find(const BrickKey& key) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = cached_.find(key.id());
  if (it == cached_.end()) return nullptr;
  lru_.splice(lru_.begin(), lru_, it->second);
  return it->second->second;
}

BrickRange meanPyramidBound(BrickRange ancestor, const std::vector<int>& fanIns, int maxStored) {
  const double top = maxStored;
  double lo = ancestor.min, hi = ancestor.max;
  for (std::size_t i = 0; i < fanIns.size() && (lo > 0.0 || hi < top); ++i) {
    const double n = fanIns[i];
    lo = std::max(0.0, n * (lo - 1.0) - (n - 1.0) * top);
    hi = std::min(top, n * (hi + 1.0));
  }
  return {static_cast<std::uint16_t>(lo), static_cast<std::uint16_t>(hi)};
}

BrickRange meanPyramidBound(BrickRange ancestor, int levelsUp, int maxStored) {
  return meanPyramidBound(ancestor, std::vector<int>(static_cast<std::size_t>(levelsUp), 8),
                          maxStored);
}

std::optional<BrickRange> BrickStreamer::range(const BrickKey& key) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = ranges_.find(key.id());
  if (it == ranges_.end()) return std::nullopt;
  return it->second;
}

bool BrickStreamer::failing(const BrickKey& key) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return failingLocked(key.id());
}

bool BrickStreamer::failingLocked(std::uint64_t id) const {
  const auto it = failures_.find(id);
  return it != failures_.end() && failingAfter(it->second);
}

bool BrickStreamer::failingAfter(const Failure& f) const {
  return f.attempts > 0 && f.attempts >= options_.attemptsBeforeFailing;
}

bool BrickStreamer::givenUp(std::uint64_t id) const {
  return !retryFailing_ && failingLocked(id);
}

void BrickStreamer::retryFailing(bool retry) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    retryFailing_ = retry;
  }
  wake_.notify_all();
}

void BrickStreamer::countFailing(const Failure& f, int delta) {
  std::uint64_t& n = failingErrors_[f.error];
  if (delta > 0) {
    ++n;
    ++stats_.failingBricks;
    return;
  }
  --stats_.failingBricks;
  if (--n == 0) failingErrors_.erase(f.error);
}

bool BrickStreamer::idle() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return queue_.empty() && reading_.empty();
}

StreamerStats BrickStreamer::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  StreamerStats s = stats_;
  s.failingErrorCount = failingErrors_.size();
  for (const auto& [error, bricks] : failingErrors_) {
    if (s.failingErrors.size() == StreamerStats::kListedErrors) break;
    s.failingErrors.push_back(error);
  }
  return s;
}

void BrickStreamer::waitForProgress(double ms) {
  std::unique_lock<std::mutex> lock(mutex_);
  progress_.wait_for(lock, std::chrono::duration<double, std::milli>(ms));
}

std::shared_ptr<const StoredBrick> BrickStreamer::readOne(const BrickKey& key) {
  return std::make_shared<const StoredBrick>(readStoredBrick(*source_, grid_, key, mapping_));
}

void BrickStreamer::store(const BrickKey& key, std::shared_ptr<const StoredBrick> brick) {
  const std::uint64_t id = key.id();
  ranges_[id] = {brick->min, brick->max};
  if (const auto f = failures_.find(id); f != failures_.end()) {
    if (failingAfter(f->second)) countFailing(f->second, -1);
    failures_.erase(f);
  }
  ++stats_.bricksRead;
  stats_.bytesRead += brick->bytes.size();
  if (cached_.count(id)) return;
  stats_.cacheBytes += brick->bytes.size();
  lru_.emplace_front(id, std::move(brick));
  cached_[id] = lru_.begin();
  // Least recently used out while over the budget (the newest always stays).
  while (stats_.cacheBytes > options_.cacheBytes && lru_.size() > 1) {
    stats_.cacheBytes -= lru_.back().second->bytes.size();
    cached_.erase(lru_.back().first);
    lru_.pop_back();
  }
  stats_.cachePeakBytes = std::max(stats_.cachePeakBytes, stats_.cacheBytes);
}

void BrickStreamer::recordFailure(const BrickKey& key, const std::string& what) {
  Failure& f = failures_[key.id()];
  if (failingAfter(f)) countFailing(f, -1);
  ++f.attempts;
  f.error = what;
  if (failingAfter(f)) countFailing(f, +1);
  const double wait =
      std::min(options_.maxRetryMs, options_.firstRetryMs * std::ldexp(1.0, f.attempts - 1));
  f.retryAtMs = nowMs() + wait;
  ++stats_.readErrors;
  stats_.lastError = what;
}

void BrickStreamer::work() {
  while (true) {
    BrickKey key;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || !queue_.empty(); });
      if (stop_) return;
      key = queue_.front();
      queue_.pop_front();
      if (cached_.count(key.id()) || givenUp(key.id()) || !reading_.insert(key.id()).second) {
        continue;
      }
    }
    std::string error;
    readAndStore(key, error);
  }
}

std::shared_ptr<const StoredBrick> BrickStreamer::readAndStore(const BrickKey& key,
                                                               std::string& error) {
  std::shared_ptr<const StoredBrick> brick;
  try {
    brick = readOne(key);
  } catch (const std::exception& e) {
    error = e.what();
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    reading_.erase(key.id());
    if (brick) {
      store(key, brick);
    } else {
      recordFailure(key, error);
    }
  }
  progress_.notify_all();
  return brick;
}

std::shared_ptr<const StoredBrick> BrickStreamer::readNow(const BrickKey& key) {
  std::string error;
  for (int attempt = 0; attempt < std::max(1, options_.attemptsBeforeFailing); ++attempt) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      progress_.wait(lock, [&] { return !reading_.count(key.id()); });
      const auto it = cached_.find(key.id());
      if (it != cached_.end()) return it->second->second;
      reading_.insert(key.id());
    }
    if (auto brick = readAndStore(key, error)) return brick;
  }
  throw Error("reading brick (level " + std::to_string(key.level) + ") failed " +
              std::to_string(options_.attemptsBeforeFailing) + " times: " + error);
}

}  // namespace tessera::lod
