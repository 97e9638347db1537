#pragma once
// A Zarr store on an HTTP(S) server, read through libcurl: keys are URLs
// under the store's root URL. A small pool of connections (one curl easy
// handle each, reused so that keep-alive connections are too) serves
// parallel requests. Every request has a connect timeout, an overall
// timeout and a stall timeout; a 5xx, 408, 429, a transport error or a
// body shorter than its Content-Length is retried with exponential
// back-off; a 404 (or 410) is an absent key (a missing chunk = fill_value,
// Zarr's semantics); other 4xx fail at once. Every error names the URL.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "tessera/io/ZarrStorage.h"

namespace tessera {

struct HttpOptions {
  int connections = 4;  // parallel requests (the pool's size)
  int attempts = 4;     // tries per request before giving up
  int backoffMs = 100;  // first retry's wait; doubles each time
  int connectTimeoutMs = 5000;
  int requestTimeoutMs = 60000;  // a whole request, transfer included
  int stallTimeoutMs = 10000;    // no byte for this long: a timeout

  // Defaults, overridden by TESSERA_HTTP_CONNECTIONS, TESSERA_HTTP_ATTEMPTS,
  // TESSERA_HTTP_TIMEOUT_MS (request) and TESSERA_HTTP_STALL_MS.
  static HttpOptions fromEnvironment();
};

// True for "http://..." and "https://...".
bool isHttpUrl(const std::string& spec);

class HttpStorage final : public ZarrStorage {
 public:
  explicit HttpStorage(std::string rootUrl, HttpOptions options = HttpOptions::fromEnvironment());
  ~HttpStorage() override;
  HttpStorage(const HttpStorage&) = delete;
  HttpStorage& operator=(const HttpStorage&) = delete;

  std::optional<std::vector<std::byte>> get(const std::string& key,
                                            std::uint64_t maxBytes) const override;
  std::string locate(const std::string& key) const override { return root_ + "/" + key; }
  int refetches() const override { return options_.attempts - 1; }
  int parallelism() const override { return options_.connections; }
  std::string describe() const override { return root_; }

  // Body bytes received (all attempts) and requests made, for reports.
  std::uint64_t bytesFetched() const { return bytes_.load(); }
  std::uint64_t requests() const { return requests_.load(); }
  std::uint64_t retries() const { return retries_.load(); }

 private:
  struct Pool;
  std::string root_;
  HttpOptions options_;
  std::unique_ptr<Pool> pool_;
  mutable std::atomic<std::uint64_t> bytes_{0};
  mutable std::atomic<std::uint64_t> requests_{0};
  mutable std::atomic<std::uint64_t> retries_{0};
};

}  // namespace tessera
