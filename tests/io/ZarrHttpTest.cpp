// OME-Zarr over HTTP, against real servers the test starts: Debian's nginx
// on 127.0.0.1 (generated config in a temp folder, a free port, stopped at
// the end), and tests/zarr/fault_proxy.py in front of it returning 500s,
// truncated and garbled bodies and stalls. The read must equal the local
// read, or fail with an error naming the URL; never crash or hang.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <thread>

#include "io/ZarrTestSupport.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/HttpStorage.h"
#include "tessera/io/VolumeReader.h"
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

class ZarrHttp : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(test::Nginx::kBinary)) GTEST_SKIP() << "nginx not installed (nginx-light)";
    fs::create_directories(tmp_ / "www");
    // 90x70x50 u16 in 16^3 chunks: 120 chunks at level 0, 4 levels.
    const Volume v = test::randomVolume({90, 70, 50}, ScalarType::U16, 42);
    OmeZarrWriteOptions o;
    o.chunk = 16;
    o.compressor = ZarrCompressor::Blosc;
    writeOmeZarr(v, tmp_ / "www" / "store.ome.zarr", o);
    // A chunk absent from the store: 404 over HTTP, fill_value (0) in both reads.
    fs::remove(tmp_ / "www" / "store.ome.zarr" / "0" / "1" / "1" / "1");
    nginx_ = std::make_unique<test::Nginx>(tmp_ / "www", tmp_ / "nginx");
  }
  std::string localStore() const { return (tmp_ / "www" / "store.ome.zarr").string(); }
  // tests/zarr/fault_proxy.py in front of nginx (`how`: its mode and its
  // arguments); the store's URL through it once it listens ("" if it did not).
  std::string proxiedStore(std::unique_ptr<test::ChildProcess>& proxy,
                           const std::vector<std::string>& how) {
    std::vector<std::string> argv = {test::kZarrPython, test::zarrScript("fault_proxy.py").string(),
                                     std::to_string(nginx_->port())};
    argv.insert(argv.end(), how.begin(), how.end());
    proxy = std::make_unique<test::ChildProcess>(argv);
    const std::string port = proxy->readLine();
    if (port.empty() || !test::waitForPort(std::stoi(port), 10.0)) return "";
    return "http://127.0.0.1:" + port + "/store.ome.zarr";
  }

  TempDir tmp_;
  std::unique_ptr<test::Nginx> nginx_;
};

TEST_F(ZarrHttp, NginxServedStoreReadsIdenticallyToTheFolder) {
  const ZarrStore local(openZarrStorage(localStore()));
  auto http = std::make_shared<HttpStorage>(nginx_->url("store.ome.zarr"));
  const ZarrStore remote(http);
  ASSERT_EQ(remote.levelCount(), local.levelCount());
  ASSERT_EQ(remote.levelCount(), 4);
  for (int l = 0; l < local.levelCount(); ++l) {
    SCOPED_TRACE(l);
    EXPECT_TRUE(sameVoxels(remote.readLevel(l), local.readLevel(l)));
    EXPECT_EQ(remote.level(l).origin, local.level(l).origin);
  }
  EXPECT_EQ(remote.readLevel(0).valueAt(16, 16, 16), 0.0);  // the missing chunk
  EXPECT_EQ(http->retries(), 0u);
  EXPECT_GT(http->bytesFetched(), 0u);
  // A box touching one chunk fetches one chunk.
  const std::uint64_t before = http->requests();
  remote.readBox(0, {17, 17, 33}, {30, 31, 47});
  EXPECT_EQ(http->requests() - before, 1u);
  // And readVolume takes the URL like a file.
  EXPECT_TRUE(sameVoxels(readVolume(nginx_->url("store.ome.zarr")), local.readLevel(0)));
}

TEST_F(ZarrHttp, FlakyProxyEveryChunkEventuallyRight) {
  std::unique_ptr<test::ChildProcess> proxy;
  const std::string url = proxiedStore(proxy, {"flaky", "3"});
  ASSERT_FALSE(url.empty());
  HttpOptions o;
  o.attempts = 4;
  o.backoffMs = 10;
  o.requestTimeoutMs = 700;  // the proxy's 3 s stall is a timeout, then a retry
  auto http = std::make_shared<HttpStorage>(url, o);
  const auto t0 = std::chrono::steady_clock::now();
  const ZarrStore remote(http);
  const ZarrStore local(openZarrStorage(localStore()));
  EXPECT_TRUE(sameVoxels(remote.readLevel(0), local.readLevel(0)));
  EXPECT_TRUE(sameVoxels(remote.readLevel(1), local.readLevel(1)));
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // 500s, truncated bodies (Content-Length check), garbled bodies (decode,
  // then refetch) and stalls (timeout) were all met and retried.
  EXPECT_GT(http->retries(), 20u);
  EXPECT_LT(s, 60.0);
}

TEST_F(ZarrHttp, ChunkThatKeepsFailingIsAnErrorNamingItsUrl) {
  std::unique_ptr<test::ChildProcess> proxy;
  const std::string url = proxiedStore(proxy, {"broken", "0", "/0/2/3/4"});
  ASSERT_FALSE(url.empty());
  HttpOptions o;
  o.attempts = 3;
  o.backoffMs = 10;
  const ZarrStore remote(std::make_shared<HttpStorage>(url, o));
  try {
    remote.readLevel(0);
    FAIL() << "a chunk that always answers 500 was read";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(url + "/0/2/3/4"), std::string::npos) << m;
    EXPECT_NE(m.find("HTTP 500"), std::string::npos) << m;
    EXPECT_NE(m.find("3 attempts"), std::string::npos) << m;
  }
  // Boxes that avoid it still read.
  EXPECT_NO_THROW(remote.readBox(0, {0, 0, 0}, {16, 16, 16}));
}

// A key that failed all its attempts fails again at once with the same error
// (no request) while remembered, and is fetched again after.
TEST_F(ZarrHttp, AKeyThatFailedFailsAtOnceWhileRemembered) {
  std::unique_ptr<test::ChildProcess> proxy;
  const std::string url = proxiedStore(proxy, {"broken", "0", "/0/2/3/4"});
  ASSERT_FALSE(url.empty());
  HttpOptions o;
  o.attempts = 3;
  o.backoffMs = 10;
  o.failureMemoryMs = 500;
  auto http = std::make_shared<HttpStorage>(url, o);
  std::string first;
  try {
    http->get("0/2/3/4", 1 << 20);
  } catch (const Error& e) {
    first = e.what();
  }
  ASSERT_NE(first.find("HTTP 500 (gave up after 3 attempts)"), std::string::npos) << first;
  EXPECT_EQ(http->requests(), 3u);
  for (int i = 0; i < 5; ++i) {
    try {
      http->get("0/2/3/4", 1 << 20);
      FAIL() << "read";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()), first);
    }
  }
  EXPECT_EQ(http->requests(), 3u) << "fetched again while remembered";
  EXPECT_TRUE(http->get("0/0/0/0", 1 << 20)) << "other keys are fetched";
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  EXPECT_THROW(http->get("0/2/3/4", 1 << 20), Error);
  EXPECT_EQ(http->requests(), 3u + 1u + 3u) << "fetched again once forgotten";
}

// A server that never answers a chunk, and one that stops half-way through
// its body: each attempt ends after the stall timeout (checked about once
// a second), not after the request timeout.
TEST_F(ZarrHttp, HangingAndStalledChunksFailWithinTheStallTimeout) {
  for (const std::string mode : {"hang", "stall"}) {
    SCOPED_TRACE(mode);
    std::unique_ptr<test::ChildProcess> proxy;
    const std::string url = proxiedStore(proxy, {mode, "0", "/0/2/3/4"});
    ASSERT_FALSE(url.empty());
    HttpOptions o;
    o.attempts = 2;
    o.backoffMs = 10;
    o.stallTimeoutMs = 1000;
    HttpStorage http(url, o);
    const auto t0 = std::chrono::steady_clock::now();
    try {
      http.get("0/2/3/4", 1 << 20);
      FAIL() << "read";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("/0/2/3/4: stalled: no byte for 1000 ms"),
                std::string::npos)
          << e.what();
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("  [measured] %s: 2 attempts failed after %.2f s (stall 1 s, bound 2 x 2 s)\n",
                mode.c_str(), s);
    EXPECT_GE(s, 2.0);
    EXPECT_LE(s, 2 * (1.0 + 1.0) + 0.1);
    EXPECT_TRUE(http.get("0/0/0/0", 1 << 20)) << "the others pass through";
  }
}

TEST_F(ZarrHttp, UnreachableServerAndMissingStoreNameTheUrl) {
  HttpOptions o;
  o.attempts = 2;
  o.backoffMs = 10;
  const std::string dead = "http://127.0.0.1:" + std::to_string(test::freePort()) + "/s.zarr";
  try {
    ZarrStore(std::make_shared<HttpStorage>(dead, o));
    FAIL() << "nothing listens there";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(dead + "/.zattrs"), std::string::npos) << e.what();
  }
  try {
    ZarrStore(std::make_shared<HttpStorage>(nginx_->url("nothing.zarr"), o));
    FAIL() << "no store there";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(nginx_->url("nothing.zarr")), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace tessera
