// A store whose chunks are much larger than bricks (microscopy's
// 32x512x512 against 32^3 bricks): the streamer's readers fetch and decode
// each chunk once per refinement, however many bricks it holds and in
// whatever order the view wants them, and the bricks hold the same values
// as bricks read without the chunk cache. Counted through a storage that
// counts its gets: exact numbers, not timings.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <mutex>
#include <random>

#include "support/CountingStorage.h"
#include "support/TestSupport.h"
#include "tessera/io/ZarrStorage.h"
#include "tessera/io/ZarrWriter.h"
#include "tessera/lod/BrickStreamer.h"
#include "tessera/lod/ZarrMultiresSource.h"

namespace tessera::lod {
namespace {

using test::CountingStorage;

Volume smooth(glm::ivec3 d) {
  Volume v = Volume::allocate(d, ScalarType::U16, "smooth");
  std::mt19937 rng(11);
  for (int z = 0; z < d.z; ++z) {
    for (int y = 0; y < d.y; ++y) {
      for (int x = 0; x < d.x; ++x) {
        v.setValueAtIndex(v.index(x, y, z),
                          double((x * 37 + y * 11 + z * 101) % 3000 + rng() % 50));
      }
    }
  }
  v.invalidateRange();
  return v;
}

struct Store {
  test::TempDir tmp;
  std::shared_ptr<CountingStorage> counting;
  std::shared_ptr<ZarrMultiresSource> cached;  // counted, decoded chunks kept
  std::shared_ptr<ZarrMultiresSource> plain;   // keeps none
};

// 80x72x40 in chunks of 64x64x32 (2x2x2 chunks at level 0, 1 at level 1)
// read as 8^3 bricks: 450 + 75 bricks, up to 256 in one chunk.
std::unique_ptr<Store> store() {
  auto s = std::make_unique<Store>();
  OmeZarrWriteOptions o;
  o.chunkShape = {64, 64, 32};
  o.compressor = ZarrCompressor::Zstd;
  const auto path = s->tmp / "big-chunks.ome.zarr";
  writeOmeZarr(smooth({80, 72, 40}), path, o);
  s->counting = std::make_shared<CountingStorage>(path);
  auto store = std::make_shared<ZarrStore>(s->counting);
  store->keepDecodedChunks(ZarrMultiresSource::decodedChunkBudget(*store, 1ull << 30));
  s->cached = std::make_shared<ZarrMultiresSource>(std::move(store));
  s->plain = std::make_shared<ZarrMultiresSource>(
      std::make_shared<ZarrStore>(std::make_shared<FolderStorage>(path)));
  s->counting->reset();  // opening may read the coarsest level for its range
  return s;
}

std::vector<BrickKey> allBricks(const BrickGrid& grid) {
  std::vector<BrickKey> keys;
  for (int l = 0; l < grid.levelCount(); ++l) {
    const glm::ivec3 n = grid.bricks(l);
    for (int z = 0; z < n.z; ++z)
      for (int y = 0; y < n.y; ++y)
        for (int x = 0; x < n.x; ++x) keys.push_back({l, {x, y, z}});
  }
  return keys;
}

TEST(ZarrChunkReads, EachChunkIsDecodedOncePerRefinementAndBricksKeepTheirValues) {
  const auto s = store();
  ASSERT_EQ(s->cached->levelCount(), 2);
  ASSERT_EQ(s->cached->levelInfo(0).chunk, glm::ivec3(64, 64, 32));
  const BrickGrid grid = BrickGrid::of(*s->cached, 8);
  std::vector<BrickKey> keys = allBricks(grid);
  ASSERT_EQ(keys.size(), 450u + 75u);
  // In no chunk order: the order a view's nearest-first request has is
  // not the chunks'.
  std::shuffle(keys.begin(), keys.end(), std::mt19937(3));
  BrickStreamerOptions o;
  o.workers = 2;
  o.cacheBytes = 1ull << 30;
  BrickStreamer streamer(s->cached, grid, o);
  streamer.request(keys);
  while (!streamer.idle()) streamer.waitForProgress(20.0);
  ASSERT_EQ(streamer.stats().bricksRead, keys.size()) << streamer.stats().lastError;

  const std::map<std::string, int> gets = s->counting->gets();
  std::map<std::string, int> once = {{"1/0/0/0", 1}};
  for (const char* zyx : {"0/0/0", "0/0/1", "0/1/0", "0/1/1", "1/0/0", "1/0/1", "1/1/0", "1/1/1"}) {
    once[std::string("0/") + zyx] = 1;
  }
  EXPECT_EQ(gets, once) << "each chunk fetched and decoded once for 525 bricks";
  const ZarrChunkCacheStats c = s->cached->store().chunkStats();
  EXPECT_EQ(c.decodes, 9u);
  // Every brick's box touches 1 to 8 chunks; all but the 9 decodes were
  // found decoded or waited for.
  EXPECT_GE(c.hits + c.waits, keys.size() - 9);

  const StoredMapping mapping = StoredMapping::of(s->plain->shape());
  ASSERT_EQ(mapping.bits, streamer.mapping().bits);
  int differing = 0;
  for (const BrickKey& k : keys) {
    const auto brick = streamer.find(k);
    ASSERT_TRUE(brick);
    const StoredBrick plain = readStoredBrick(*s->plain, grid, k, mapping);
    if (brick->bytes != plain.bytes || brick->min != plain.min || brick->max != plain.max) {
      ++differing;
    }
  }
  EXPECT_EQ(differing, 0) << "bricks read through the chunk cache equal bricks read without";

  // A second refinement of the same view finds every chunk decoded.
  s->counting->reset();
  BrickStreamer again(s->cached, grid, o);
  again.request(keys);
  while (!again.idle()) again.waitForProgress(20.0);
  EXPECT_TRUE(s->counting->gets().empty());
}

// The budget the source derives: every chunk of the store when an eighth of
// the host budget holds them, else that eighth.
TEST(ZarrChunkReads, TheDecodedChunkBudgetIsTheStoresChunksWithinAnEighthOfTheHost) {
  const auto s = store();
  const ZarrStore& store = s->cached->store();
  // Level 0: 8 chunks of 64x64x32 u16; level 1 (40x36x20): one chunk capped
  // at the level's dims.
  const std::uint64_t all = 8ull * 64 * 64 * 32 * 2 + 40ull * 36 * 20 * 2;
  EXPECT_EQ(store.allChunkBytes(), all);
  EXPECT_EQ(store.chunkCacheBytes(), all);
  EXPECT_EQ(ZarrMultiresSource::decodedChunkBudget(store, 8 * all), all);
  EXPECT_EQ(ZarrMultiresSource::decodedChunkBudget(store, 8 * all - 8), all - 1);
  EXPECT_EQ(ZarrMultiresSource::decodedChunkBudget(store, 1ull << 20), 128ull << 10);
}

// A source that records the chunk (of 64x64x32) holding each box it reads.
class RecordingSource final : public MultiresSource {
 public:
  explicit RecordingSource(std::shared_ptr<const MultiresSource> inner)
      : inner_(std::move(inner)) {}
  const Volume& shape() const override { return inner_->shape(); }
  int levelCount() const override { return inner_->levelCount(); }
  LevelInfo levelInfo(int level) const override { return inner_->levelInfo(level); }
  Volume readBox(int level, const VoxelBox& box) const override {
    const glm::ivec3 c = (box.begin + box.end) / 2 / glm::ivec3(64, 64, 32);
    {
      const std::lock_guard lock(mutex_);
      chunks_.push_back(level * 100 + c.x + 2 * c.y + 4 * c.z);
    }
    return inner_->readBox(level, box);
  }
  std::string describe() const override { return inner_->describe(); }
  std::vector<int> chunks() const {
    const std::lock_guard lock(mutex_);
    return chunks_;
  }

 private:
  std::shared_ptr<const MultiresSource> inner_;
  mutable std::mutex mutex_;
  mutable std::vector<int> chunks_;
};

// Without workers (the browser) the reads follow the queue: the bricks of
// one chunk are read one after the other, their chunks in the order the
// request first wants each (so the urgent brick's chunk comes first).
TEST(ZarrChunkReads, TheQueueReadsTheBricksOfOneChunkTogether) {
  const auto s = store();
  const BrickGrid grid = BrickGrid::of(*s->cached, 8);
  std::vector<BrickKey> keys = allBricks(grid);
  std::shuffle(keys.begin(), keys.end(), std::mt19937(9));
  auto recording = std::make_shared<RecordingSource>(s->cached);
  std::vector<int> wanted;  // chunks in the order of first want
  for (const BrickKey& k : keys) {
    const VoxelBox b = grid.readBox(k);
    const glm::ivec3 c = (b.begin + b.end) / 2 / glm::ivec3(64, 64, 32);
    const int chunk = k.level * 100 + c.x + 2 * c.y + 4 * c.z;
    if (std::find(wanted.begin(), wanted.end(), chunk) == wanted.end()) wanted.push_back(chunk);
  }
  ASSERT_EQ(wanted.size(), 9u);

  BrickStreamerOptions o;
  o.workers = 0;
  o.inlineReadsPerRequest = int(keys.size());
  o.cacheBytes = 1ull << 30;
  BrickStreamer streamer(recording, grid, o);
  streamer.request(keys);
  EXPECT_EQ(streamer.stats().bricksRead, keys.size());
  std::vector<int> runs;  // the chunk of each run of reads of one chunk
  const std::vector<int> read = recording->chunks();
  for (const int chunk : read)
    if (runs.empty() || runs.back() != chunk) runs.push_back(chunk);
  EXPECT_EQ(runs, wanted);
}

}  // namespace
}  // namespace tessera::lod
