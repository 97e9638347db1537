#include "tessera/io/HttpStorage.h"

#include <curl/curl.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdlib>
#include <mutex>
#include <random>
#include <thread>
#include <vector>

#include "tessera/core/Error.h"

namespace tessera {

namespace {

int envInt(const char* name, int fallback, int lo, int hi) {
  const char* v = std::getenv(name);
  if (!v) return fallback;
  char* end = nullptr;
  const long n = std::strtol(v, &end, 10);
  if (end == v || *end != '\0' || n < lo || n > hi) {
    throw InputError(std::string(name) + "='" + v + "': expected an integer in " +
                     std::to_string(lo) + ".." + std::to_string(hi));
  }
  return static_cast<int>(n);
}

void globalInit() {
  static std::once_flag once;
  std::call_once(once, [] { curl_global_init(CURL_GLOBAL_DEFAULT); });
}

struct Body {
  std::vector<std::byte> bytes;
  std::string contentRange;  // "bytes 0-99/1234" of a 206
  std::uint64_t limit = 0;
  bool tooBig = false;
  // The stall check: the request's start or its last body byte.
  std::chrono::steady_clock::time_point lastByte = std::chrono::steady_clock::now();
  std::chrono::milliseconds stallAfter{0};
  bool stalled = false;
};

std::size_t onBody(char* data, std::size_t size, std::size_t count, void* user) {
  auto* body = static_cast<Body*>(user);
  const std::size_t n = size * count;
  if (body->bytes.size() + n > body->limit) {
    body->tooBig = true;
    return 0;  // aborts the transfer (CURLE_WRITE_ERROR)
  }
  const auto* p = reinterpret_cast<const std::byte*>(data);
  body->bytes.insert(body->bytes.end(), p, p + n);
  body->lastByte = std::chrono::steady_clock::now();
  return n;
}

std::size_t onHeader(char* data, std::size_t size, std::size_t count, void* user) {
  auto* body = static_cast<Body*>(user);
  const std::string line(data, size * count);
  constexpr const char* kName = "content-range:";
  if (line.size() > 14) {
    std::string head = line.substr(0, 14);
    std::transform(head.begin(), head.end(), head.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (head == kName) body->contentRange = line.substr(14);
  }
  return size * count;
}

// The whole value's size in a Content-Range ("bytes 0-99/1234"); 0 if
// none is given.
std::uint64_t rangeTotal(const std::string& header) {
  const auto slash = header.find('/');
  if (slash == std::string::npos) return 0;
  return std::strtoull(header.c_str() + slash + 1, nullptr, 10);
}

// Called by libcurl at least once a second: a request whose answer has not
// begun or whose body has stopped for stallAfter is aborted. (libcurl's
// LOW_SPEED_TIME averages the speed over its last 5 s, so a body that stops
// half-way was only caught 5 s late.)
int onProgress(void* user, curl_off_t, curl_off_t, curl_off_t, curl_off_t) {
  auto* body = static_cast<Body*>(user);
  body->stalled = std::chrono::steady_clock::now() - body->lastByte > body->stallAfter;
  return body->stalled ? 1 : 0;  // non-zero aborts (CURLE_ABORTED_BY_CALLBACK)
}

}  // namespace

HttpOptions HttpOptions::fromEnvironment() {
  HttpOptions o;
  o.connections = envInt("TESSERA_HTTP_CONNECTIONS", o.connections, 1, 64);
  o.attempts = envInt("TESSERA_HTTP_ATTEMPTS", o.attempts, 1, 20);
  o.requestTimeoutMs = envInt("TESSERA_HTTP_TIMEOUT_MS", o.requestTimeoutMs, 100, 3600000);
  o.stallTimeoutMs = envInt("TESSERA_HTTP_STALL_MS", o.stallTimeoutMs, 1000, 3600000);
  return o;
}

bool isHttpUrl(const std::string& spec) {
  return spec.rfind("http://", 0) == 0 || spec.rfind("https://", 0) == 0;
}

// Idle easy handles; each keeps its connections alive between requests.
struct HttpStorage::Pool {
  std::mutex mutex;
  std::vector<CURL*> idle;
  ~Pool() {
    for (CURL* h : idle) curl_easy_cleanup(h);
  }
  CURL* acquire() {
    {
      const std::lock_guard lock(mutex);
      if (!idle.empty()) {
        CURL* h = idle.back();
        idle.pop_back();
        return h;
      }
    }
    CURL* h = curl_easy_init();
    if (!h) throw Error("libcurl: curl_easy_init failed");
    return h;
  }
  void release(CURL* h) {
    const std::lock_guard lock(mutex);
    idle.push_back(h);
  }
};

HttpStorage::HttpStorage(std::string rootUrl, HttpOptions options)
    : root_(std::move(rootUrl)), options_(options), pool_(std::make_unique<Pool>()) {
  globalInit();
  while (!root_.empty() && root_.back() == '/') root_.pop_back();
}

HttpStorage::~HttpStorage() = default;

void HttpStorage::throwIfFailedRecently(const std::string& url) const {
  const std::lock_guard lock(failedMutex_);
  const auto it = failed_.find(url);
  if (it == failed_.end()) return;
  if (std::chrono::steady_clock::now() < it->second.until) throw Error(it->second.error);
  failed_.erase(it);
}

void HttpStorage::fail(const std::string& url, const std::string& error,
                       std::chrono::steady_clock::time_point started) const {
  const auto now = std::chrono::steady_clock::now();
  const auto memory = std::max<std::chrono::steady_clock::duration>(
      std::chrono::milliseconds(options_.failureMemoryMs), now - started);
  {
    const std::lock_guard lock(failedMutex_);
    failed_[url] = {error, now + memory};
  }
  throw Error(error);
}

std::optional<std::vector<std::byte>> HttpStorage::get(const std::string& key,
                                                       std::uint64_t maxBytes) const {
  const std::string url = locate(key);
  HttpResponse r = request(url, url, {}, maxBytes, "");
  if (r.status == 404 || r.status == 410) return std::nullopt;
  if (r.status < 200 || r.status >= 300) {
    throw InputError(url + ": HTTP " + std::to_string(r.status));
  }
  return std::move(r.body);
}

HttpResponse HttpStorage::fetch(const std::string& url, const std::vector<std::string>& headers,
                                std::uint64_t maxBytes) const {
  return request(url, url, headers, maxBytes, "");
}

std::optional<ZarrRange> HttpStorage::getRange(const std::string& key, std::int64_t offset,
                                               std::uint64_t length, std::uint64_t maxWhole) const {
  const std::string url = locate(key);
  std::string range;  // appended, not "-" + string: GCC 12's -Wrestrict false positive
  if (offset < 0) {
    range.append("-").append(std::to_string(length));
  } else {
    range.append(std::to_string(offset))
        .append("-")
        .append(std::to_string(std::uint64_t(offset) + length - 1));
  }
  if (length == 0) throw InputError(url + ": an empty range asked");
  std::string label = url;
  label.append(" (bytes ").append(range).append(")");
  HttpResponse r = request(url, label, {}, std::max(length, maxWhole), range);
  if (r.status == 404 || r.status == 410) return std::nullopt;
  if (r.status == 416) throw InputError(label + ": HTTP 416, the range lies outside the value");
  if (r.status < 200 || r.status >= 300) {
    throw InputError(label + ": HTTP " + std::to_string(r.status));
  }
  if (r.status != 206) {
    // The server ignored Range (200 with the whole body): cut it out here.
    ++wholeBodies_;
    const std::uint64_t total = r.body.size();
    const std::uint64_t begin =
        offset < 0 ? total - std::min(total, length) : std::uint64_t(offset);
    if ((offset < 0 && length > total) || begin > total || length > total - begin) {
      throw InputError(url + ": bytes " + range + " asked of a value of " + std::to_string(total) +
                       " bytes");
    }
    ZarrRange out;
    out.total = total;
    out.bytes.assign(r.body.begin() + std::ptrdiff_t(begin),
                     r.body.begin() + std::ptrdiff_t(begin + length));
    return out;
  }
  if (r.rangeTotal == 0) throw InputError(label + ": HTTP 206 without a Content-Range total");
  if (r.body.size() != length) {
    throw InputError(url + ": range " + range + " answered with " + std::to_string(r.body.size()) +
                     " bytes, expected " + std::to_string(length));
  }
  if (r.rangeTotal > maxWhole) {
    throw InputError(url + ": " + std::to_string(r.rangeTotal) + " bytes, more than the " +
                     std::to_string(maxWhole) + " any valid content of this key can have");
  }
  return ZarrRange{std::move(r.body), r.rangeTotal};
}

HttpResponse HttpStorage::request(const std::string& url, const std::string& label,
                                  const std::vector<std::string>& headers, std::uint64_t maxBytes,
                                  const std::string& range) const {
  throwIfFailedRecently(label);
  const auto started = std::chrono::steady_clock::now();
  CURL* h = pool_->acquire();
  struct Return {
    Pool& pool;
    CURL* h;
    ~Return() { pool.release(h); }
  } giveBack{*pool_, h};
  struct HeaderList {
    curl_slist* list = nullptr;
    ~HeaderList() { curl_slist_free_all(list); }
  } headerList;
  for (const std::string& header : headers) {
    curl_slist* grown = curl_slist_append(headerList.list, header.c_str());
    if (!grown) throw Error("libcurl: curl_slist_append failed");
    headerList.list = grown;
  }
  std::string problem;
  thread_local std::mt19937 jitter(std::random_device{}());
  for (int attempt = 0; attempt < options_.attempts; ++attempt) {
    if (attempt > 0) {
      ++retries_;
      const int wait = options_.backoffMs << std::min(attempt - 1, 10);
      std::this_thread::sleep_for(std::chrono::milliseconds(
          wait + static_cast<int>(jitter() % static_cast<unsigned>(wait / 2 + 1))));
    }
    Body body;
    body.limit = maxBytes;
    char error[CURL_ERROR_SIZE] = {0};
    curl_easy_reset(h);
    curl_easy_setopt(h, CURLOPT_URL, url.c_str());
    if (!range.empty()) curl_easy_setopt(h, CURLOPT_RANGE, range.c_str());
    if (headerList.list) curl_easy_setopt(h, CURLOPT_HTTPHEADER, headerList.list);
    curl_easy_setopt(h, CURLOPT_HEADERFUNCTION, onHeader);
    curl_easy_setopt(h, CURLOPT_HEADERDATA, &body);
    curl_easy_setopt(h, CURLOPT_WRITEFUNCTION, onBody);
    curl_easy_setopt(h, CURLOPT_WRITEDATA, &body);
    curl_easy_setopt(h, CURLOPT_ERRORBUFFER, error);
    curl_easy_setopt(h, CURLOPT_NOSIGNAL, 1L);
    curl_easy_setopt(h, CURLOPT_FOLLOWLOCATION, 1L);
    curl_easy_setopt(h, CURLOPT_MAXREDIRS, 5L);
    curl_easy_setopt(h, CURLOPT_CONNECTTIMEOUT_MS, long(options_.connectTimeoutMs));
    curl_easy_setopt(h, CURLOPT_TIMEOUT_MS, long(options_.requestTimeoutMs));
    // A stall: no body byte for stallTimeoutMs, from the start (a server
    // that never answers) or from the last byte (a body that stops).
    body.stallAfter = std::chrono::milliseconds(options_.stallTimeoutMs);
    curl_easy_setopt(h, CURLOPT_NOPROGRESS, 0L);
    curl_easy_setopt(h, CURLOPT_XFERINFOFUNCTION, onProgress);
    curl_easy_setopt(h, CURLOPT_XFERINFODATA, &body);
    ++requests_;
    const CURLcode rc = curl_easy_perform(h);
    bytes_ += body.bytes.size();
    if (body.tooBig) {
      throw InputError(label + ": more than " + std::to_string(maxBytes) +
                       " bytes, more than any valid content of this key can have");
    }
    if (body.stalled) {
      problem = "stalled: no byte for " + std::to_string(options_.stallTimeoutMs) +
                " ms (TESSERA_HTTP_STALL_MS)";
      continue;
    }
    if (rc != CURLE_OK) {
      problem = std::string(curl_easy_strerror(rc)) + (error[0] ? std::string(": ") + error : "");
      continue;
    }
    long status = 0;
    curl_easy_getinfo(h, CURLINFO_RESPONSE_CODE, &status);
    if (status >= 500 || status == 408 || status == 429) {
      problem = "HTTP " + std::to_string(status);
      continue;
    }
    curl_off_t declared = -1;
    curl_easy_getinfo(h, CURLINFO_CONTENT_LENGTH_DOWNLOAD_T, &declared);
    if (status >= 200 && status < 300 && declared >= 0 &&
        std::uint64_t(declared) != body.bytes.size()) {
      problem = "received " + std::to_string(body.bytes.size()) + " of the " +
                std::to_string(declared) + " bytes of Content-Length";
      continue;
    }
    const char* type = nullptr;
    curl_easy_getinfo(h, CURLINFO_CONTENT_TYPE, &type);
    HttpResponse response{status, type ? type : "", std::move(body.bytes), 0};
    if (status == 206) response.rangeTotal = rangeTotal(body.contentRange);
    return response;
  }
  fail(label,
       label + ": " + problem + " (gave up after " + std::to_string(options_.attempts) +
           " attempts)",
       started);
}

}  // namespace tessera
