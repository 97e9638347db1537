#pragma once
// Reads bricks of a MultiresSource on worker threads into an LRU cache of
// stored bricks that stays within a host byte budget (DESIGN.md "Large
// data"; Schultz 2016 §7.3 loads sub-volumes on demand). The render loop
// asks each frame for the bricks it wants, nearest first (request()); the
// workers take them in that order, bricks never tried before bricks whose
// reads failed. A read that throws is retried later with exponential
// back-off, so the coarser level stays on screen meanwhile; after
// attemptsBeforeFailing failures the brick is failing: the viewers keep
// retrying it (a server may come back), a run that refines to completion
// gives it up (retryFailing(false)). The range of every brick ever read is
// kept (16 bytes a brick) after the brick itself leaves the cache, for
// empty-space decisions.
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "tessera/lod/BrickGrid.h"
#include "tessera/lod/MultiresSource.h"

namespace tessera::lod {

struct BrickStreamerOptions {
  int workers = 2;                         // 0: request() reads inline
  int inlineReadsPerRequest = 8;           // without workers
  std::uint64_t cacheBytes = 64ull << 20;  // decoded bricks kept on the host
  // The failure policy. A brick's k-th failed read (k = 1, 2, ...) waits
  // min(maxRetryMs, firstRetryMs * 2^(k-1)) before the next; after
  // attemptsBeforeFailing failed reads failing() is true. Giving a brick up
  // therefore takes attemptsBeforeFailing reads (each as long as the source
  // takes to fail: HttpStorage's own retries and timeouts) plus the waits
  // between them (20 + 40 ms by default).
  double firstRetryMs = 20.0;
  double maxRetryMs = 2000.0;
  int attemptsBeforeFailing = 3;
  // Without workers: queued bricks whose source is not ready yet
  // (MultiresSource::prefetch) looked at per request before it gives up.
  int prefetchAhead = 16;
};

struct BrickRange {  // in stored units (StoredMapping)
  std::uint16_t min = 0;
  std::uint16_t max = 0;
};

// What a brick tells of the stored values (0..M, M = maxStored, 0 = the
// smallest the mapping stores) of the bricks under it, in a mean pyramid
// (MultiresSource::meanPyramid()) stored exactly (StoredMapping::exact): a
// coarse voxel m is the mean of at most n finer ones (n = the level's
// BrickGrid::fanIn: 8 for factors (2, 2, 2), 4 for (1, 2, 2)), none below 0
// or above M, so each of them lies in [n m - (n - 1) M, n m]; rounding of
// the stored means adds one either way. `fanIns`: n of each level from the
// brick's down to the bricks bounded (the brick's own first). The bound
// widens n-fold a level; it is tight where it matters, over empty space (a
// coarse maximum of 0 bounds every finer voxel at n), and a lone bright
// voxel averaged into a dim coarse one is never bounded away.
BrickRange meanPyramidBound(BrickRange ancestor, const std::vector<int>& fanIns, int maxStored);
// The same `levelsUp` levels down a factor-2 pyramid (n = 8 a level).
BrickRange meanPyramidBound(BrickRange ancestor, int levelsUp, int maxStored);

struct StreamerStats {
  std::uint64_t bricksRead = 0;
  std::uint64_t bytesRead = 0;  // stored bytes of the bricks read
  std::uint64_t readErrors = 0;
  std::uint64_t cacheBytes = 0;
  std::uint64_t cachePeakBytes = 0;
  std::string lastError;
  // The bricks failing now (BrickStreamer::failing), and their distinct
  // last errors (each names the chunk, file or URL that failed), sorted, at
  // most kListedErrors of failingErrorCount.
  std::uint64_t failingBricks = 0;
  std::vector<std::string> failingErrors;
  std::size_t failingErrorCount = 0;
  static constexpr std::size_t kListedErrors = 8;
};

class BrickStreamer {
 public:
  BrickStreamer(std::shared_ptr<const MultiresSource> source, BrickGrid grid,
                BrickStreamerOptions options);
  ~BrickStreamer();
  BrickStreamer(const BrickStreamer&) = delete;
  BrickStreamer& operator=(const BrickStreamer&) = delete;

  const BrickGrid& grid() const { return grid_; }
  const StoredMapping& mapping() const { return mapping_; }

  // The bricks wanted now, most urgent first: replaces the queue of reads not
  // yet started with those of `keys` that are neither cached, being read,
  // nor waiting out a back-off. Bricks of one source chunk (LevelInfo::
  // chunk) are queued together, in the order their chunks are first
  // wanted: the readers then take a chunk's bricks one after the other and
  // the source decodes it once (io/ZarrChunkCache.h) however large it is.
  void request(const std::vector<BrickKey>& keys);
  // The cached brick (and marks it recently used), or null.
  std::shared_ptr<const StoredBrick> find(const BrickKey& key);
  // Reads on this thread (or waits for a worker already reading it),
  // retrying up to attemptsBeforeFailing times; throws the last error.
  std::shared_ptr<const StoredBrick> readNow(const BrickKey& key);
  // The brick's exact range if it was ever read.
  std::optional<BrickRange> range(const BrickKey& key) const;
  // True once the brick's reads failed attemptsBeforeFailing times in a row.
  bool failing(const BrickKey& key) const;
  // Whether a failing brick is read again after its back-off (the default:
  // a viewer keeps trying, the server may come back). false gives failing
  // bricks up: request() and the workers skip them, so a run that refines
  // to completion ends within the failure policy's time and no read of a
  // given-up brick is left in flight.
  void retryFailing(bool retry);
  // Without workers: how many queued bricks one request() reads (0: none,
  // they wait for a later request).
  void setInlineReadsPerRequest(int count) { options_.inlineReadsPerRequest = count; }
  // Waits until a read finishes or `ms` pass.
  void waitForProgress(double ms);
  bool idle() const;  // nothing queued or being read
  StreamerStats stats() const;

 private:
  struct Failure {
    int attempts = 0;
    double retryAtMs = 0.0;
    std::string error;  // the last read's
  };
  bool failingAfter(const Failure& f) const;
  bool failingLocked(std::uint64_t id) const;  // lock held
  bool givenUp(std::uint64_t id) const;        // lock held
  // The failing bricks' errors, counted per message (lock held).
  void countFailing(const Failure& f, int delta);
  void work();
  void readQueuedInline(int count);
  // `keys` grouped by the chunk that holds each (stable otherwise).
  std::vector<BrickKey> groupedByChunk(std::vector<BrickKey> keys) const;
  std::shared_ptr<const StoredBrick> readOne(const BrickKey& key);            // no lock held
  void store(const BrickKey& key, std::shared_ptr<const StoredBrick> brick);  // lock held
  void recordFailure(const BrickKey& key, const std::string& what);           // lock held
  // Reads `key` (its id already in reading_), then stores it or records the
  // failure (its message in `error`) and wakes the waiters. No lock held;
  // null on failure.
  std::shared_ptr<const StoredBrick> readAndStore(const BrickKey& key, std::string& error);
  double nowMs() const;

  std::shared_ptr<const MultiresSource> source_;
  BrickGrid grid_;
  StoredMapping mapping_;
  BrickStreamerOptions options_;
  std::vector<glm::ivec3> chunks_;  // per level (0: the source has none)

  mutable std::mutex mutex_;
  std::condition_variable wake_;      // workers: the queue changed or stop
  std::condition_variable progress_;  // readers: a read finished
  std::deque<BrickKey> queue_;
  std::unordered_set<std::uint64_t> reading_;
  std::list<std::pair<std::uint64_t, std::shared_ptr<const StoredBrick>>> lru_;
  std::unordered_map<std::uint64_t, decltype(lru_)::iterator> cached_;
  std::unordered_map<std::uint64_t, BrickRange> ranges_;
  std::unordered_map<std::uint64_t, Failure> failures_;
  std::map<std::string, std::uint64_t> failingErrors_;  // message -> failing bricks
  bool retryFailing_ = true;
  StreamerStats stats_;
  bool stop_ = false;
  std::vector<std::thread> workers_;
};

}  // namespace tessera::lod
