#pragma once
// A Zarr store on an HTTP(S) server, read through libcurl: keys are URLs
// under the store's root URL. A small pool of connections (one curl easy
// handle each, reused so that keep-alive connections are too) serves
// parallel requests. Every request has a connect timeout, an overall
// timeout and a stall timeout; a 5xx, 408, 429, a transport error or a
// body shorter than its Content-Length is retried with exponential
// back-off; a 404 (or 410) is an absent key (a missing chunk = fill_value,
// Zarr's semantics); other 4xx fail at once. Every error names the URL.
// One get() of a key that keeps failing takes at most
//   attempts * (the request's time: <= requestTimeoutMs, and <= the
//   stall timeout past its last byte) + the back-off waits (100, 200, 400 ms
//   by default, each up to 1.5x with jitter),
// e.g. 4 x 500: about 1 s; a server that accepts and never answers: 4 x 5 s
// + 1 s. A key whose attempts all failed then fails at once with the same
// error for a while (failureMemoryMs) instead of being fetched again.
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include "tessera/io/ZarrStorage.h"

namespace tessera {

struct HttpOptions {
  int connections = 4;  // parallel requests (the pool's size)
  int attempts = 4;     // tries per request before giving up
  int backoffMs = 100;  // first retry's wait; doubles each time
  int connectTimeoutMs = 5000;
  int requestTimeoutMs = 60000;  // a whole request, transfer included
  // No byte for this long (waiting for the answer or inside the body): a
  // timeout, then a retry.
  int stallTimeoutMs = 5000;
  // After a key failed all its attempts, get() fails at once with the same
  // error for max(failureMemoryMs, the time those attempts took): the
  // bricks around one dead chunk (each reads it for its apron) and the
  // streamer's own retries do not fetch it again and again. The page's
  // fetch storage waits 3 s too.
  int failureMemoryMs = 3000;

  // Defaults, overridden by TESSERA_HTTP_CONNECTIONS, TESSERA_HTTP_ATTEMPTS,
  // TESSERA_HTTP_TIMEOUT_MS (request) and TESSERA_HTTP_STALL_MS.
  static HttpOptions fromEnvironment();
};

// True for "http://..." and "https://...".
bool isHttpUrl(const std::string& spec);

// One answer of HttpStorage::fetch: its final status (after the retries),
// Content-Type and body.
struct HttpResponse {
  long status = 0;
  std::string contentType;
  std::vector<std::byte> body;
  std::uint64_t rangeTotal = 0;  // a 206's whole value (Content-Range); 0 otherwise
};

class HttpStorage final : public ZarrStorage {
 public:
  explicit HttpStorage(std::string rootUrl, HttpOptions options = HttpOptions::fromEnvironment());
  ~HttpStorage() override;
  HttpStorage(const HttpStorage&) = delete;
  HttpStorage& operator=(const HttpStorage&) = delete;

  std::optional<std::vector<std::byte>> get(const std::string& key,
                                            std::uint64_t maxBytes) const override;
  // A Range request; a server that ignores Range (200 with the whole
  // body) still works, its body cut here (counted in wholeBodies()).
  std::optional<ZarrRange> getRange(const std::string& key, std::int64_t offset,
                                    std::uint64_t length, std::uint64_t maxWhole) const override;
  std::string locate(const std::string& key) const override { return root_ + "/" + key; }

  // GET `url` (any URL, not only under the root) with extra request headers
  // ("Name: value"; never printed or logged, errors name the URL only), the
  // body at most `maxBytes` (InputError past that). Retried and remembered
  // as get(); any other status (2xx, 4xx) is returned for the caller to judge.
  HttpResponse fetch(const std::string& url, const std::vector<std::string>& headers,
                     std::uint64_t maxBytes) const;
  int refetches() const override { return options_.attempts - 1; }
  int parallelism() const override { return options_.connections; }
  std::string describe() const override { return root_; }

  // Body bytes received (all attempts) and requests made, for reports.
  std::uint64_t bytesFetched() const { return bytes_.load(); }
  std::uint64_t requests() const { return requests_.load(); }
  std::uint64_t retries() const { return retries_.load(); }
  // Range requests answered with the whole body (200).
  std::uint64_t wholeBodies() const { return wholeBodies_.load(); }

 private:
  struct Pool;
  // One GET of `url` (with a Range when `range` is not empty: "0-99",
  // "-100"; with `headers`), retried as the class comment says; errors and
  // the failure memory name `label`. Any final status is returned.
  HttpResponse request(const std::string& url, const std::string& label,
                       const std::vector<std::string>& headers, std::uint64_t maxBytes,
                       const std::string& range) const;
  struct Failed {
    std::string error;
    std::chrono::steady_clock::time_point until;
  };
  // Throws the remembered error if `url` failed recently.
  void throwIfFailedRecently(const std::string& url) const;
  [[noreturn]] void fail(const std::string& url, const std::string& error,
                         std::chrono::steady_clock::time_point started) const;

  std::string root_;
  HttpOptions options_;
  std::unique_ptr<Pool> pool_;
  mutable std::atomic<std::uint64_t> bytes_{0};
  mutable std::atomic<std::uint64_t> requests_{0};
  mutable std::atomic<std::uint64_t> retries_{0};
  mutable std::atomic<std::uint64_t> wholeBodies_{0};
  mutable std::mutex failedMutex_;
  mutable std::unordered_map<std::string, Failed> failed_;  // by URL
};

}  // namespace tessera
