// io::ZarrChunkCache: decoded chunks least recently used first out within
// the budget, and a chunk being decoded shared with a second thread that
// wants it (it waits and gets the first's chunk or error).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

#include "tessera/io/ZarrChunkCache.h"

namespace tessera {
namespace {

ZarrChunkCache::Chunk bytes(std::size_t n) {
  return std::make_shared<const std::vector<std::byte>>(n, std::byte{7});
}

TEST(ZarrChunkCache, KeepsTheMostRecentlyUsedChunksWithinTheBudget) {
  // Room for two 1000-byte chunks with their bookkeeping, not three.
  ZarrChunkCache cache(2500);
  int decodes = 0;
  const auto decode = [&] {
    ++decodes;
    return bytes(1000);
  };
  const auto a = cache.get("0/0/0/0", decode);
  cache.get("0/0/0/1", decode);
  EXPECT_EQ(cache.get("0/0/0/0", decode), a) << "found, the same bytes";
  cache.get("0/0/1/0", decode);  // evicts 0/0/0/1, the least recently used
  EXPECT_EQ(decodes, 3);
  cache.get("0/0/0/0", decode);
  EXPECT_EQ(decodes, 3);
  cache.get("0/0/0/1", decode);
  EXPECT_EQ(decodes, 4);
  const ZarrChunkCacheStats s = cache.stats();
  EXPECT_EQ(s.decodes, 4u);
  EXPECT_EQ(s.hits, 2u);
  EXPECT_LE(s.heldBytes, 2500u);
  EXPECT_LE(s.peakBytes, 2500u);
  EXPECT_GE(s.heldBytes, 2000u);
  // A missing chunk (fill_value) is remembered as null.
  EXPECT_EQ(cache.get("0/9/9/9", [&] { return ZarrChunkCache::Chunk(); }), nullptr);
  EXPECT_EQ(cache.get("0/9/9/9", decode), nullptr);
  // A chunk over the budget is handed out, not kept.
  ZarrChunkCache small(100);
  small.get("k", decode);
  small.get("k", decode);
  EXPECT_EQ(decodes, 6);
  EXPECT_EQ(small.stats().heldBytes, 0u);
}

// The first thread's decode does not finish until the second is waiting
// for the same chunk: the second gets the first's bytes, decoded once.
TEST(ZarrChunkCache, ASecondReaderWaitsForTheChunkBeingDecoded) {
  ZarrChunkCache cache(1 << 20);
  std::atomic<int> decodes{0};
  const auto slow = [&] {
    ++decodes;
    while (cache.stats().waits == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return bytes(4096);
  };
  ZarrChunkCache::Chunk first, second;
  std::thread t([&] { first = cache.get("1/0/0/0", slow); });
  while (decodes == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  second = cache.get("1/0/0/0", [&] {
    ++decodes;
    return bytes(4096);
  });
  t.join();
  EXPECT_EQ(decodes, 1);
  EXPECT_EQ(first, second);
  EXPECT_EQ(cache.stats().waits, 1u);
}

// A failed decode: the waiter gets its error; the next get decodes again.
TEST(ZarrChunkCache, AFailedDecodeIsSharedWithTheWaiterAndNotRemembered) {
  ZarrChunkCache cache(1 << 20);
  std::atomic<int> decodes{0};
  const auto failing = [&]() -> ZarrChunkCache::Chunk {
    ++decodes;
    while (cache.stats().waits == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    throw std::runtime_error("0/1/2/3: corrupt zstd frame");
  };
  std::string firstError;
  std::thread t([&] {
    try {
      cache.get("0/1/2/3", failing);
    } catch (const std::runtime_error& e) {
      firstError = e.what();
    }
  });
  while (decodes == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  std::string secondError;
  try {
    cache.get("0/1/2/3", [&] { return bytes(8); });
  } catch (const std::runtime_error& e) {
    secondError = e.what();
  }
  t.join();
  EXPECT_EQ(decodes, 1);
  EXPECT_EQ(firstError, "0/1/2/3: corrupt zstd frame");
  EXPECT_EQ(secondError, firstError);
  EXPECT_EQ(cache.get("0/1/2/3", [&] { return bytes(8); })->size(), 8u);
}

}  // namespace
}  // namespace tessera
