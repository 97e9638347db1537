// QIDO-RS and WADO-RS (PS3.18 10.6 and 10.4) over HttpStorage's pool; the
// series is assembled by the folder reader's code (io/DicomSeries.cpp) from
// the metadata, its frames fetched and decoded in parallel.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include "io/DicomSeries.h"
#include "io/DicomWebFrame.h"
#include "io/DicomWebInstance.h"
#include "io/DicomWebParts.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/io/ByteSource.h"
#include "tessera/io/DicomWeb.h"
#include "tessera/io/HttpStorage.h"

namespace tessera {

namespace {

using io_detail::DicomJsonAttributes;
using io_detail::DicomTag;
using io_detail::Slice;

// Larger answers are no QIDO or metadata answer of a series that could be
// read: the metadata of 4,000 instances is under 40 MiB.
constexpr std::uint64_t kMaxJsonBytes = 256ull << 20;
// A part's headers and the boundaries around one frame.
constexpr std::uint64_t kMultipartOverhead = 64 * 1024;
// A compressed frame is never much larger than the pixels it holds (JPEG
// lossless and JPEG 2000 at worst a few percent over); twice is the bound.
constexpr std::uint64_t kCompressedExpansion = 2;

constexpr DicomTag kSopInstanceUid{0x0008, 0x0018};
constexpr DicomTag kStudyInstanceUid{0x0020, 0x000d};
constexpr DicomTag kPatientName{0x0010, 0x0010};
constexpr DicomTag kPatientId{0x0010, 0x0020};
constexpr DicomTag kStudyDate{0x0008, 0x0020};
constexpr DicomTag kStudyDescription{0x0008, 0x1030};
constexpr DicomTag kModalitiesInStudy{0x0008, 0x0061};
constexpr DicomTag kStudySeries{0x0020, 0x1206};
constexpr DicomTag kStudyInstances{0x0020, 0x1208};
constexpr DicomTag kSeriesNumber{0x0020, 0x0011};
constexpr DicomTag kSeriesInstances{0x0020, 0x1209};

const char* kJsonAccept = "Accept: application/dicom+json";
const char* kFrameAccept =
    "Accept: multipart/related; type=\"application/octet-stream\"; "
    "transfer-syntax=*";

long number(const DicomJsonAttributes& a, DicomTag tag) {
  const auto t = a.text(tag);
  if (!t || t->empty()) return -1;
  char* end = nullptr;
  const long n = std::strtol(t->c_str(), &end, 10);
  return end != t->c_str() && *end == '\0' ? n : -1;
}

std::string textOf(const DicomJsonAttributes& a, DicomTag tag) {
  return a.text(tag).value_or("");
}

}  // namespace

bool isDicomWebSeriesUrl(const std::string& spec) {
  if (!isHttpUrl(spec)) return false;
  std::string s = spec;
  while (!s.empty() && s.back() == '/') s.pop_back();
  const auto series = s.rfind("/series/");
  if (series == std::string::npos || series + 8 >= s.size()) return false;
  const auto studies = s.rfind("/studies/", series);
  return studies != std::string::npos && studies + 9 < series &&
         s.find('/', studies + 9) == series && s.find('/', series + 8) == std::string::npos;
}

DicomWebSeriesUrl parseDicomWebSeriesUrl(const std::string& url) {
  if (!isDicomWebSeriesUrl(url)) {
    throw InputError(url + ": not a DICOMweb series URL (expected ROOT/studies/UID/series/UID)");
  }
  std::string s = url;
  while (!s.empty() && s.back() == '/') s.pop_back();
  const auto series = s.rfind("/series/");
  const auto studies = s.rfind("/studies/", series);
  return {s.substr(0, studies), s.substr(studies + 9, series - studies - 9), s.substr(series + 8)};
}

DicomWebOptions DicomWebOptions::fromEnvironment() {
  DicomWebOptions o;
  if (const char* auth = std::getenv("TESSERA_DICOMWEB_AUTH"); auth && *auth) {
    o.headers.push_back(std::string("Authorization: ") + auth);
  }
  return o;
}

namespace {

// One line for an answer that is not 2xx; never the credentials, only
// whether some were sent.
[[noreturn]] void refuse(const std::string& url, long status, bool credentials) {
  std::string why = "HTTP " + std::to_string(status);
  if (status == 401) {
    why += credentials ? " Unauthorized: the credentials given were refused"
                       : " Unauthorized: the server wants credentials (set TESSERA_DICOMWEB_AUTH "
                         "to the Authorization header's value, e.g. 'Basic <base64 of "
                         "user:password>', or pass --header)";
  } else if (status == 403) {
    why += " Forbidden: the credentials given do not allow this";
  } else if (status == 404) {
    why += " Not Found: no such study, series or instance, or not a DICOMweb service root";
  }
  throw InputError(url + ": " + why);
}

}  // namespace

DicomWebClient::DicomWebClient(std::string root, DicomWebOptions options)
    : root_(std::move(root)), options_(std::move(options)) {
  while (!root_.empty() && root_.back() == '/') root_.pop_back();
  if (!isHttpUrl(root_)) throw InputError(root_ + ": not an http:// or https:// URL");
  http_ = std::make_unique<HttpStorage>(root_);
}

DicomWebClient::~DicomWebClient() = default;

namespace {

nlohmann::json getJson(const HttpStorage& http, const std::string& url,
                       const std::vector<std::string>& headers, bool credentials) {
  std::vector<std::string> h = headers;
  h.push_back(kJsonAccept);
  const HttpResponse r = http.fetch(url, h, kMaxJsonBytes);
  if (r.status == 204) return nlohmann::json::array();  // QIDO: no match
  if (r.status < 200 || r.status >= 300) refuse(url, r.status, credentials);
  return io_detail::parseDicomJson(r.body, url);
}

}  // namespace

std::vector<DicomWebStudy> DicomWebClient::studies(const std::string& query) const {
  const std::string url = root_ +
                          "/studies?includefield=00081030&includefield=00080061&includefield="
                          "00201206&includefield=00201208" +
                          (query.empty() ? "" : "&" + query);
  const nlohmann::json j = getJson(*http_, url, options_.headers, !options_.headers.empty());
  std::vector<DicomWebStudy> out;
  for (const nlohmann::json& d : j) {
    const DicomJsonAttributes a(d);
    out.push_back({textOf(a, kStudyInstanceUid), textOf(a, kPatientName), textOf(a, kPatientId),
                   textOf(a, kStudyDate), textOf(a, kStudyDescription),
                   textOf(a, kModalitiesInStudy), number(a, kStudySeries),
                   number(a, kStudyInstances)});
    if (out.back().uid.empty()) {
      throw InputError(url + ": study " + std::to_string(out.size()) +
                       " of the answer has no Study Instance UID (0020,000D)");
    }
  }
  return out;
}

std::vector<DicomWebSeries> DicomWebClient::series(const std::string& studyUid) const {
  const std::string url = root_ + "/studies/" + studyUid +
                          "/series?includefield=0008103E&includefield=00200011&includefield="
                          "00201209";
  const nlohmann::json j = getJson(*http_, url, options_.headers, !options_.headers.empty());
  std::vector<DicomWebSeries> out;
  for (const nlohmann::json& d : j) {
    const DicomJsonAttributes a(d);
    DicomWebSeries s{studyUid,
                     textOf(a, io_detail::kTagSeriesInstanceUid),
                     textOf(a, io_detail::kTagModality),
                     textOf(a, io_detail::kTagSeriesDescription),
                     number(a, kSeriesNumber),
                     number(a, kSeriesInstances),
                     ""};
    if (s.uid.empty()) {
      throw InputError(url + ": series " + std::to_string(out.size() + 1) +
                       " of the answer has no Series Instance UID (0020,000E)");
    }
    s.url = root_ + "/studies/" + studyUid + "/series/" + s.uid;
    out.push_back(std::move(s));
  }
  std::sort(out.begin(), out.end(),
            [](const DicomWebSeries& a, const DicomWebSeries& b) { return a.number < b.number; });
  return out;
}

namespace {

// A Part-10 instance holds its header besides its frames: the functional
// groups of an enhanced object take some KiB per frame.
constexpr std::uint64_t kInstanceOverhead = 16ull << 20;

// Frames asked in one request (.../frames/1,2,...): a multi-frame object's
// request stays a few hundred bytes of URL and some MiB of answer.
constexpr std::size_t kFramesPerRequest = 64;

const char* kInstanceAccept =
    "Accept: multipart/related; type=\"application/dicom\"; transfer-syntax=*";

std::uint64_t pixelBytesOf(const Slice& s) {
  return static_cast<std::uint64_t>(s.rows) * static_cast<std::uint64_t>(s.columns) *
         static_cast<std::uint64_t>(std::max(1, s.bitsAllocated / 8));
}

// The slices of one instance: a single-frame file's one, or the frames of a
// multi-frame object (in frame order), fetched together.
struct InstanceFrames {
  std::string url;  // ROOT/studies/S/series/S/instances/SOP
  std::vector<const Slice*> frames;
};

std::vector<InstanceFrames> byInstance(const std::vector<Slice>& all) {
  std::vector<InstanceFrames> out;
  std::map<std::string, std::size_t> index;
  for (const Slice& s : all) {
    const auto [it, added] = index.emplace(s.file.string(), out.size());
    if (added) out.push_back({s.file.string(), {}});
    out[it->second].frames.push_back(&s);
  }
  for (InstanceFrames& i : out) {
    std::sort(i.frames.begin(), i.frames.end(),
              [](const Slice* a, const Slice* b) { return a->frame < b->frame; });
  }
  return out;
}

// The frames of a series' slices, fetched and decoded in parallel on first
// use (the series code asks for them one by one, in z order, once its
// checks have passed): one WADO-RS request per instance, for all its
// frames (.../frames/1,2,3). Archives that cannot send an instance's frames
// alone (Orthanc 1.10 answers HTTP 500 for HTJ2K frames; 400, 406 and 501
// say the same) send the whole instance instead, and its frames are cut out
// of the file (io/DicomWebInstance.h) for the same decoders. The first
// instance is asked once without retries, so that such an archive costs one
// failed request, and the rest of the series is then asked whole.
class FrameFetcher {
 public:
  FrameFetcher(const HttpStorage& http, const HttpStorage& probe, std::vector<std::string> headers,
               int connections, std::string seriesUrl)
      : http_(http),
        probe_(probe),
        headers_(std::move(headers)),
        connections_(std::max(1, connections)),
        seriesUrl_(std::move(seriesUrl)) {}

  io_detail::StoredRange decode(const Slice& s, const std::vector<Slice>& all, Volume& stored,
                                int z) {
    if (!fetched_) fetchAll(all);
    const auto it = frames_.find(io_detail::sliceName(s));
    if (it == frames_.end()) throw Error(io_detail::sliceName(s) + ": frame was not fetched");
    const io_detail::StoredRange r =
        io_detail::storePixels(s, it->second.data(), it->second.size(), stored, z);
    frames_.erase(it);  // held no longer than needed
    return r;
  }

  std::vector<std::string> syntaxes() const {
    const std::lock_guard lock(mutex_);
    return {syntaxes_.begin(), syntaxes_.end()};
  }
  std::uint64_t wholeInstances() const { return wholeCount_; }

 private:
  using Frames = std::vector<std::vector<std::byte>>;

  void noteSyntax(const std::string& syntax) {
    const std::lock_guard lock(mutex_);
    if (std::find(syntaxes_.begin(), syntaxes_.end(), syntax) == syntaxes_.end()) {
      syntaxes_.push_back(syntax);
    }
  }

  std::vector<std::string> headers(const char* accept) const {
    std::vector<std::string> h = headers_;
    h.push_back(accept);
    return h;
  }

  // The instance's frames as frames (multipart/related, one part each),
  // kFramesPerRequest at a time; nullopt when the archive cannot send them
  // so: a request failed (a 5xx after its retries, a connection that
  // failed) or was answered 400, 406 or 501. `failure` then says how.
  std::optional<Frames> asFrames(const InstanceFrames& inst, const HttpStorage& via,
                                 bool credentials, std::string& failure) {
    Frames out;
    for (std::size_t from = 0; from < inst.frames.size(); from += kFramesPerRequest) {
      const std::size_t n = std::min(kFramesPerRequest, inst.frames.size() - from);
      std::string list;
      for (std::size_t k = from; k < from + n; ++k) {
        if (!list.empty()) list += ',';  // appended: GCC 12's -Wrestrict false positive
        list += std::to_string(inst.frames[k]->frame + 1);
      }
      const std::string url = inst.url + "/frames/" + list;
      HttpResponse r;
      try {
        r = via.fetch(
            url, headers(kFrameAccept),
            n * (pixelBytesOf(*inst.frames.front()) * kCompressedExpansion + kMultipartOverhead));
      } catch (const InputError&) {
        throw;  // an answer too large: a whole instance would be larger
      } catch (const Error& e) {
        failure = e.what();
        return std::nullopt;
      }
      if (r.status == 400 || r.status == 406 || r.status == 501) {
        failure = url + ": HTTP " + std::to_string(r.status);
        return std::nullopt;
      }
      if (r.status < 200 || r.status >= 300) refuse(url, r.status, credentials);
      const auto parts = io_detail::parseMultipart(r.contentType, r.body, url, n);
      if (parts.size() != n) {
        throw InputError(url + ": " + std::to_string(parts.size()) + " parts for " +
                         std::to_string(n) + " frames");
      }
      for (std::size_t k = 0; k < n; ++k) {
        const std::string syntax = io_detail::frameTransferSyntax(parts[k].contentType);
        if (syntax.empty()) {
          throw InputError(url + ": the frame's Content-Type '" +
                           parts[k].contentType.substr(0, 80) + "' names no transfer syntax");
        }
        noteSyntax(syntax);
        const std::string what = n == 1 ? url : url + " (part " + std::to_string(k + 1) + ")";
        out.push_back(
            io_detail::decodeWebFrame(*inst.frames[from + k], syntax, parts[k].body, what));
      }
    }
    return out;
  }

  // The instance as the archive stores it (a Part-10 file), its frames cut
  // out of it and decoded.
  Frames asInstance(const InstanceFrames& inst, bool credentials) {
    const Slice& first = *inst.frames.front();
    const std::uint64_t limit = static_cast<std::uint64_t>(std::max(1L, first.frames)) *
                                    pixelBytesOf(first) * kCompressedExpansion +
                                kInstanceOverhead;
    const HttpResponse r = http_.fetch(inst.url, headers(kInstanceAccept), limit);
    if (r.status < 200 || r.status >= 300) refuse(inst.url, r.status, credentials);
    const auto parts = io_detail::parseMultipart(r.contentType, r.body, inst.url, 1);
    const MemorySource file(inst.url, parts.front().body);
    Frames out;
    for (const Slice* f : inst.frames) {
      const io_detail::InstanceFrame frame = io_detail::instanceFrame(file, *f);
      noteSyntax(frame.transferSyntax);
      const std::string what =
          f->frames > 1 ? inst.url + " frame " + std::to_string(f->frame + 1) : inst.url;
      out.push_back(io_detail::decodeWebFrame(*f, frame.transferSyntax, frame.bytes, what));
    }
    ++wholeCount_;
    return out;
  }

  Frames fetchOne(const InstanceFrames& inst, bool credentials, bool probe) {
    if (!whole_) {
      std::string failure;
      if (auto frames = asFrames(inst, probe ? probe_ : http_, credentials, failure)) {
        return std::move(*frames);
      }
      whole_ = true;  // the rest of the series likewise
      try {
        return asInstance(inst, credentials);
      } catch (const Error& e) {
        throw InputError(failure + "; and the instance itself: " + e.what());
      }
    }
    return asInstance(inst, credentials);
  }

  void fetchAll(const std::vector<Slice>& all) {
    fetched_ = true;
    const std::vector<InstanceFrames> instances = byInstance(all);
    const bool credentials = !headers_.empty();
    std::atomic<std::size_t> next{1};
    std::atomic<std::size_t> done{0};
    std::atomic<bool> failed{false};
    std::exception_ptr error;
    std::size_t errorIndex = instances.size();
    const bool tty = ::isatty(2) != 0;
    const auto t0 = std::chrono::steady_clock::now();
    const auto one = [&](std::size_t i) {
      try {
        Frames frames = fetchOne(instances[i], credentials, i == 0);
        const std::lock_guard lock(mutex_);
        for (std::size_t k = 0; k < frames.size(); ++k) {
          frames_.emplace(io_detail::sliceName(*instances[i].frames[k]), std::move(frames[k]));
        }
      } catch (...) {
        const std::lock_guard lock(mutex_);
        // The first instance's error, of those that failed, is the one told.
        if (i < errorIndex) {
          errorIndex = i;
          error = std::current_exception();
        }
        failed = true;
        return false;
      }
      const std::size_t n = done += instances[i].frames.size();
      if (tty && all.size() >= 32) {
        const double sec =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::fprintf(stderr, "\rreading %s: %zu/%zu frames  %.1f s%s", seriesUrl_.c_str(), n,
                     all.size(), sec, n == all.size() ? "\n" : "");
      }
      return true;
    };
    const auto work = [&] {
      for (;;) {
        const std::size_t i = next++;
        if (i >= instances.size() || failed || !one(i)) return;
      }
    };
    // The first instance alone: it tells whether the archive sends frames.
    if (!instances.empty() && one(0)) {
      const int n = static_cast<int>(std::min<std::size_t>(connections_, instances.size()));
      std::vector<std::thread> threads;
      for (int t = 1; t < n; ++t) threads.emplace_back(work);
      work();
      for (auto& t : threads) t.join();
    }
    if (error) std::rethrow_exception(error);
  }

  const HttpStorage& http_;
  const HttpStorage& probe_;
  std::vector<std::string> headers_;
  int connections_;
  std::string seriesUrl_;
  bool fetched_ = false;
  std::atomic<bool> whole_{false};
  std::atomic<std::uint64_t> wholeCount_{0};
  mutable std::mutex mutex_;
  std::map<std::string, std::vector<std::byte>> frames_;
  std::vector<std::string> syntaxes_;
};

}  // namespace

// The series' instances as the slices a folder scan finds (one per frame
// of a multi-frame object), from its WADO-RS metadata.
io_detail::FolderScan DicomWebClient::scanSeries(const std::string& seriesUrl) const {
  const bool credentials = !options_.headers.empty();
  const std::string metadataUrl = seriesUrl + "/metadata";
  const nlohmann::json datasets = getJson(*http_, metadataUrl, options_.headers, credentials);

  io_detail::FolderScan scan;
  scan.where = "DICOMweb series " + seriesUrl;
  for (std::size_t i = 0; i < datasets.size(); ++i) {
    const DicomJsonAttributes a(datasets[i]);
    const std::string sop = textOf(a, kSopInstanceUid);
    if (sop.empty() || sop.find('/') != std::string::npos || sop.size() > 64) {
      throw InputError(metadataUrl + ": instance " + std::to_string(i + 1) +
                       " has no valid SOP Instance UID (0008,0018)");
    }
    if (!a.has(io_detail::kTagPixelData) && !a.has(io_detail::kTagRows)) {
      ++scan.nonImageObjects;
      continue;
    }
    Slice s = io_detail::sliceHeader(seriesUrl + "/instances/" + sop, a);
    s.transferSyntax = "as stored (WADO-RS transfer-syntax=*)";
    // A multi-frame object (enhanced CT/MR: its functional groups are in the
    // metadata) becomes one slice per frame, as in a folder.
    for (Slice& frame : io_detail::framesOf(std::move(s), a)) {
      scan.slices.push_back(std::move(frame));
    }
  }
  return scan;
}

std::vector<DicomSeriesInfo> DicomWebClient::stacks(const std::string& studyUid,
                                                    const std::string& seriesUid) const {
  return io_detail::listSeries(scanSeries(root_ + "/studies/" + studyUid + "/series/" + seriesUid));
}

Volume DicomWebClient::readSeries(const std::string& studyUid, const std::string& seriesUid,
                                  const std::string& stack) const {
  const std::string seriesUrl = root_ + "/studies/" + studyUid + "/series/" + seriesUid;
  io_detail::FolderScan scan = scanSeries(seriesUrl);
  const std::vector<Slice> all = scan.slices;
  HttpOptions once = HttpOptions::fromEnvironment();
  once.attempts = 1;
  once.connections = 1;
  const HttpStorage probe(root_, once);
  FrameFetcher fetcher(*http_, probe, options_.headers, http_->parallelism(), seriesUrl);
  // A stack of a series of several ("UID:stack", as --series takes for a
  // folder); without one, the largest, the others named in the description.
  Volume v = io_detail::readSeries(
      std::move(scan), stack.empty() ? seriesUid : seriesUid + ":" + stack, seriesUrl,
      [&](const Slice& s, Volume& stored, int z) { return fetcher.decode(s, all, stored, z); });
  syntaxes_ = fetcher.syntaxes();
  probeBytes_ += probe.bytesFetched();
  probeRequests_ += probe.requests();
  wholeInstances_ += fetcher.wholeInstances();
  std::string received;
  for (const std::string& t : syntaxes_) received += (received.empty() ? "" : ", ") + t;
  const DicomWebTransfer t = transfer();
  v.setDescription(v.description() + "; frames received in transfer syntax " + received +
                   (t.wholeInstances > 0
                        ? " (" + std::to_string(t.wholeInstances) +
                              " instances retrieved whole: the archive does not send their "
                              "frames alone)"
                        : std::string()) +
                   "; " + formatBytes(t.bytes) + " in " + std::to_string(t.requests) + " requests");
  return v;
}

DicomWebTransfer DicomWebClient::transfer() const {
  return {http_->bytesFetched() + probeBytes_, http_->requests() + probeRequests_, http_->retries(),
          syntaxes_, wholeInstances_};
}

Volume readDicomWebSeries(const std::string& url, DicomWebTransfer* transfer,
                          const std::string& selection) {
  const DicomWebSeriesUrl u = parseDicomWebSeriesUrl(url);
  const DicomWebClient client(u.root);
  Volume v = client.readSeries(u.study, u.series, dicomWebStack(url, selection));
  if (transfer) *transfer = client.transfer();
  return v;
}

std::string dicomWebStack(const std::string& url, const std::string& selection) {
  if (selection.empty()) return "";
  const std::string series = parseDicomWebSeriesUrl(url).series;
  if (selection == series) return "";
  if (selection.starts_with(series + ":") && selection.size() > series.size() + 1) {
    return selection.substr(series.size() + 1);
  }
  throw InputError(url + ": --series " + selection + " is not the series the URL names (" + series +
                   ", or " + series +
                   ":STACK for one of its stacks; `tessera info URL` lists them)");
}

std::vector<DicomSeriesInfo> listDicomWebSeries(const std::string& url) {
  const DicomWebSeriesUrl u = parseDicomWebSeriesUrl(url);
  const DicomWebClient client(u.root);
  return client.stacks(u.study, u.series);
}

}  // namespace tessera
