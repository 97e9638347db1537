// A sharded Zarr v3 store over HTTP from nginx (the server the v2 HTTP
// tests start): a shard's index is read once with a range request, then
// only the inner chunks a box needs, each with its own range (counted:
// requests and bytes). Behind a location with `max_ranges 0` nginx ignores
// Range and answers 200 with the whole shard: the read is still right.
#include <gtest/gtest.h>

#include <cstring>

#include "io/ZarrTestSupport.h"
#include "support/TestSupport.h"
#include "tessera/io/HttpStorage.h"
#include "tessera/io/ZarrStore.h"
#include "tessera/io/ZarrWriter.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

bool sameVoxels(const Volume& a, const Volume& b) {
  return a.dims() == b.dims() && a.type() == b.type() &&
         std::memcmp(a.bytes().data(), b.bytes().data(), a.byteSize()) == 0;
}

class ZarrV3Http : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(test::Nginx::kBinary)) GTEST_SKIP() << "nginx not installed (nginx-light)";
    fs::create_directories(tmp_ / "www" / "whole");
    // 96x80x64 u16 in 16^3 chunks, 4^3 chunks per shard: level 0 is
    // 2x2x1 shards of up to 64 inner chunks.
    const Volume v = test::randomVolume({96, 80, 64}, ScalarType::U16, 5);
    OmeZarrWriteOptions o;
    o.chunk = 16;
    o.zarrFormat = 3;
    o.shard = 4;
    writeOmeZarr(v, tmp_ / "www" / "s.ome.zarr", o);
    fs::create_directory_symlink(tmp_ / "www" / "s.ome.zarr",
                                 tmp_ / "www" / "whole" / "s.ome.zarr");
    nginx_ = std::make_unique<test::Nginx>(tmp_ / "www", tmp_ / "nginx",
                                           "location /whole/ { max_ranges 0; }");
  }
  std::string local() const { return (tmp_ / "www" / "s.ome.zarr").string(); }

  TempDir tmp_;
  std::unique_ptr<test::Nginx> nginx_;
};

TEST_F(ZarrV3Http, ShardIndexOnceThenOnlyTheInnerChunksABoxNeeds) {
  const ZarrStore folder(openZarrStorage(local()));
  auto http = std::make_shared<HttpStorage>(nginx_->url("s.ome.zarr"));
  const ZarrStore remote(http);
  ASSERT_EQ(remote.levelCount(), folder.levelCount());
  const std::uint64_t r0 = http->requests(), b0 = http->bytesFetched();
  // One inner chunk (16^3 u16 = 8 KiB raw): the index, then that chunk.
  EXPECT_TRUE(sameVoxels(remote.readBox(0, {17, 17, 17}, {30, 31, 31}),
                         folder.readBox(0, {17, 17, 17}, {30, 31, 31})));
  EXPECT_EQ(http->requests() - r0, 2u);
  const std::uint64_t oneChunk = http->bytesFetched() - b0;
  const std::uint64_t shardFile =
      fs::file_size(tmp_ / "www" / "s.ome.zarr" / "0" / "c" / "0" / "0" / "0");
  EXPECT_LT(oneChunk, 8192u + 64 * 16 + 4 + 512);  // one compressed chunk + the index
  EXPECT_LT(oneChunk * 20, shardFile);
  // A second chunk of the same shard: one request (the index is cached).
  const std::uint64_t r1 = http->requests();
  remote.readBox(0, {33, 17, 17}, {40, 30, 30});
  EXPECT_EQ(http->requests() - r1, 1u);
  EXPECT_EQ(http->wholeBodies(), 0u);
  // Whole levels equal the folder read.
  for (int l = 0; l < folder.levelCount(); ++l) {
    SCOPED_TRACE(l);
    EXPECT_TRUE(sameVoxels(remote.readLevel(l), folder.readLevel(l)));
  }
  std::printf("[ figures  ] one inner chunk: 2 requests, %llu bytes (shard file %llu bytes)\n",
              static_cast<unsigned long long>(oneChunk),
              static_cast<unsigned long long>(shardFile));
}

TEST_F(ZarrV3Http, AServerThatIgnoresRangeStillReadsRight) {
  const ZarrStore folder(openZarrStorage(local()));
  auto http = std::make_shared<HttpStorage>(nginx_->url("whole/s.ome.zarr"));
  const ZarrStore remote(http);
  EXPECT_TRUE(sameVoxels(remote.readBox(0, {5, 9, 3}, {90, 70, 60}),
                         folder.readBox(0, {5, 9, 3}, {90, 70, 60})));
  EXPECT_TRUE(sameVoxels(remote.readLevel(1), folder.readLevel(1)));
  // Every range came back as the whole shard (200), cut here.
  EXPECT_GT(http->wholeBodies(), 10u);
  EXPECT_EQ(http->retries(), 0u);
}

}  // namespace
}  // namespace tessera
