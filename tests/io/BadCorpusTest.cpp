// The bad-input corpus (tests/data/bad/, written by scripts/make_bad_corpus.py):
// every case must be refused by readVolume() with an InputError or a
// BudgetError that names the file and the problem, within a second, and
// without allocating more than the file can justify.
#include <gtest/gtest.h>
#include <malloc.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <new>
#include <ostream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/io/VolumeReader.h"

// Bytes handed out by operator new and not yet returned, and their high-water
// mark since the last reset. This replaces the global operator new of test_io:
// the readers' buffers (std::vector, DCMTK's new[]) all come through here.
// While a case runs, one allocation over kRefuseAbove is refused with
// bad_alloc, so that a reader trying to allocate gigabytes fails this test
// instead of the machine.
namespace {
std::atomic<std::uint64_t> gLiveBytes{0};
std::atomic<std::uint64_t> gPeakBytes{0};
std::atomic<bool> gRefuseHuge{false};
// The largest single request, granted or not: DCMTK asks with new(nothrow)
// and survives a refusal, so only the request shows what it tried.
std::atomic<std::uint64_t> gLargestRequest{0};
constexpr std::size_t kRefuseAbove = std::size_t{1} << 30;

void* countedAlloc(std::size_t n) {
  std::uint64_t largest = gLargestRequest.load(std::memory_order_relaxed);
  while (n > largest && !gLargestRequest.compare_exchange_weak(largest, n)) {
  }
  if (gRefuseHuge.load(std::memory_order_relaxed) && n > kRefuseAbove) throw std::bad_alloc();
  void* p = std::malloc(n == 0 ? 1 : n);
  if (p == nullptr) throw std::bad_alloc();
  const std::uint64_t live =
      gLiveBytes.fetch_add(malloc_usable_size(p), std::memory_order_relaxed) +
      malloc_usable_size(p);
  std::uint64_t peak = gPeakBytes.load(std::memory_order_relaxed);
  while (live > peak && !gPeakBytes.compare_exchange_weak(peak, live)) {
  }
  return p;
}

void countedFree(void* p) noexcept {
  if (p == nullptr) return;
  gLiveBytes.fetch_sub(malloc_usable_size(p), std::memory_order_relaxed);
  std::free(p);
}
}  // namespace

// Every non-aligned form, so that no block is allocated by one allocator and
// freed by another (ASan's own operator new would otherwise serve the
// nothrow forms std::stable_sort uses). Aligned forms stay the library's.
void* operator new(std::size_t n) {
  return countedAlloc(n);
}
void* operator new[](std::size_t n) {
  return countedAlloc(n);
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return countedAlloc(n);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t& tag) noexcept {
  return operator new(n, tag);
}
void operator delete(void* p) noexcept {
  countedFree(p);
}
void operator delete[](void* p) noexcept {
  countedFree(p);
}
void operator delete(void* p, std::size_t) noexcept {
  countedFree(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  countedFree(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  countedFree(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  countedFree(p);
}

namespace tessera {
namespace {

namespace fs = std::filesystem;

constexpr std::uint64_t kBudget = 256ull << 20;
// Rejecting a file may cost at most this much CPU time (all threads of the
// process): CPU time, not wall time, so a loaded CI machine (two cores shared
// by ctest -j2, or ASan) does not fail it, while a reader that inflates a
// bomb or loops still does. kHangSeconds of wall time catches a reader that
// waits instead of working.
constexpr double kMaxSeconds = 1.0;
constexpr double kHangSeconds = 15.0;
// Fixed costs any reader may have regardless of the input: read and inflate
// buffers (a few MiB), DCMTK's dictionary, error strings.
constexpr std::uint64_t kAllocationSlack = 24ull << 20;
// A file of n bytes can justify at most n × 1032 inflated bytes (deflate's
// limit) held once as inflated data and once as the volume.
constexpr std::uint64_t kJustifiedPerInputByte = 2 * 1032;

const fs::path& badRoot() {
  static const fs::path root = fs::path(TESSERA_TEST_DATA_DIR) / "bad";
  return root;
}

struct BadCase {
  std::string file;    // relative to tests/data/bad
  std::string format;  // the reader it exercises
  std::string problem;
  std::string expect;  // "a|b": the message contains a or b (case-insensitive)
  std::vector<std::string> companions;
};

nlohmann::json loadManifest() {
  std::ifstream in(badRoot() / "MANIFEST.json");
  if (!in) return nlohmann::json::object();
  return nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
}

std::vector<BadCase> manifestCases() {
  std::vector<BadCase> cases;
  const nlohmann::json m = loadManifest();
  if (!m.is_object() || !m.contains("cases") || !m["cases"].is_array()) return cases;
  for (const auto& c : m["cases"]) {
    BadCase bc;
    bc.file = c.value("file", "");
    bc.format = c.value("format", "");
    bc.problem = c.value("problem", "");
    bc.expect = c.value("expect", "");
    if (c.contains("companions")) {
      for (const auto& f : c["companions"]) bc.companions.push_back(f.get<std::string>());
    }
    cases.push_back(bc);
  }
  return cases;
}

std::string lowered(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::vector<std::string> alternatives(const std::string& expect) {
  std::vector<std::string> out;
  std::stringstream ss(expect);
  std::string part;
  while (std::getline(ss, part, '|')) out.push_back(part);
  return out;
}

// Bytes of the case's input: a file with its companions, or a folder's files.
std::uint64_t inputBytes(const BadCase& c) {
  const fs::path p = badRoot() / c.file;
  std::uint64_t total = 0;
  if (fs::is_directory(p)) {
    for (const auto& e : fs::recursive_directory_iterator(p)) {
      if (e.is_regular_file()) total += e.file_size();
    }
  } else if (fs::exists(p)) {
    total += fs::file_size(p);
  }
  for (const auto& comp : c.companions) {
    if (fs::exists(badRoot() / comp)) total += fs::file_size(badRoot() / comp);
  }
  return total;
}

// Per-format tally of the cases run in this process, printed at the end.
struct Tally {
  std::map<std::string, std::pair<int, int>> byFormat;  // format -> (rejected cleanly, run)
};
Tally& tally() {
  static Tally t;
  return t;
}

class TallyPrinter : public ::testing::Environment {
 public:
  void TearDown() override {
    if (tally().byFormat.empty()) return;
    std::printf("bad corpus, rejected cleanly / run, by format:");
    int ok = 0;
    int run = 0;
    for (const auto& [format, counts] : tally().byFormat) {
      std::printf(" %s %d/%d", format.c_str(), counts.first, counts.second);
      ok += counts.first;
      run += counts.second;
    }
    std::printf("; total %d/%d\n", ok, run);
  }
};
[[maybe_unused]] ::testing::Environment* const kTallyPrinter =
    ::testing::AddGlobalTestEnvironment(new TallyPrinter);

// gtest prints a failing parameter with this instead of as raw bytes.
void PrintTo(const BadCase& c, std::ostream* os) {
  *os << c.format << " " << c.file;
}

class BadCorpusCase : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadCorpusCase, IsRejectedCleanly) {
  const BadCase& c = GetParam();
  const std::string path = (badRoot() / c.file).string();
  ASSERT_TRUE(fs::exists(path)) << path << " is listed in MANIFEST.json but missing";
  SCOPED_TRACE(c.format + " case " + c.file + ": " + c.problem);

  const std::uint64_t justified = inputBytes(c) * kJustifiedPerInputByte + kAllocationSlack;
  std::string message;
  std::string failure;
  std::uint64_t peak = 0;
  std::uint64_t largest = 0;
  const auto start = std::chrono::steady_clock::now();
  const std::clock_t cpuStart = std::clock();
  {
    const test::BudgetOverride budget(kBudget);
    const std::uint64_t liveBefore = gLiveBytes.load();
    gPeakBytes.store(liveBefore);
    gLargestRequest.store(0);
    gRefuseHuge.store(true);
    try {
      readVolume(path);
      failure = "was accepted; expected an InputError or BudgetError";
    } catch (const InputError& e) {
      message = e.what();
    } catch (const BudgetError& e) {
      message = e.what();
    } catch (const Error& e) {
      failure = std::string("threw a tessera::Error that is neither InputError nor BudgetError: ") +
                e.what();
    } catch (const std::bad_alloc&) {
      failure = "threw std::bad_alloc (an allocation over " + formatBytes(kRefuseAbove) +
                " was refused, or memory ran out)";
    } catch (const std::exception& e) {
      failure = std::string("threw a non-Tessera exception: ") + e.what();
    } catch (...) {
      failure = "threw something that is not a std::exception";
    }
    gRefuseHuge.store(false);
    peak = gPeakBytes.load() - liveBefore;
    largest = gLargestRequest.load();
  }
  const double seconds = double(std::clock() - cpuStart) / CLOCKS_PER_SEC;
  const double wallSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // TESSERA_BAD_CORPUS_VERBOSE=1 shows every message, to review their wording.
  if (const char* v = std::getenv("TESSERA_BAD_CORPUS_VERBOSE"); v != nullptr && *v == '1') {
    std::printf("[%s] %s\n    -> %s%s\n", c.format.c_str(), c.file.c_str(),
                failure.empty() ? message.c_str() : failure.c_str(),
                failure.empty() ? "" : " (FAILED)");
  }
  bool clean = failure.empty();
  EXPECT_TRUE(failure.empty()) << path << " " << failure;
  if (failure.empty()) {
    EXPECT_NE(message.find(path), std::string::npos)
        << "the message does not name " << path << ": " << message;
    bool found = false;
    for (const auto& alt : alternatives(c.expect)) {
      if (!alt.empty() && lowered(message).find(lowered(alt)) != std::string::npos) found = true;
    }
    EXPECT_TRUE(found) << "message lacks '" << c.expect << "': " << message;
    clean = clean && found && message.find(path) != std::string::npos;
  }
  EXPECT_LT(seconds, kMaxSeconds) << "rejecting it took " << seconds << " s of CPU time";
  EXPECT_LT(wallSeconds, kHangSeconds) << "rejecting it took " << wallSeconds << " s of wall time";
  EXPECT_LE(peak, justified) << "peak allocation " << formatBytes(peak) << " for "
                             << formatBytes(inputBytes(c)) << " of input (at most "
                             << formatBytes(justified) << " is justified)";
  EXPECT_LE(largest, justified) << "tried to allocate " << formatBytes(largest) << " at once for "
                                << formatBytes(inputBytes(c)) << " of input (at most "
                                << formatBytes(justified) << " is justified)";
  clean = clean && seconds < kMaxSeconds && wallSeconds < kHangSeconds && peak <= justified &&
          largest <= justified;
  auto& counts = tally().byFormat[c.format];
  counts.first += clean ? 1 : 0;
  counts.second += 1;
}

std::string caseName(const ::testing::TestParamInfo<BadCase>& info) {
  std::string name = info.param.file;
  for (char& ch : name) {
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  }
  return name;
}

// Device profiles are not volumes: test_gpu's DeviceProfile tests replay
// their cases (test_io does not link the gpu layer).
std::vector<BadCase> volumeCases() {
  std::vector<BadCase> cases = manifestCases();
  std::erase_if(cases, [](const BadCase& c) { return c.format == "device_profile"; });
  return cases;
}

INSTANTIATE_TEST_SUITE_P(BadCorpus, BadCorpusCase, ::testing::ValuesIn(volumeCases()), caseName);

TEST(BadCorpusManifest, ListsEveryFileAndEnoughCases) {
  ASSERT_TRUE(fs::exists(badRoot() / "MANIFEST.json"))
      << "run scripts/make_bad_corpus.py to write " << (badRoot() / "MANIFEST.json").string();
  const nlohmann::json m = loadManifest();
  ASSERT_TRUE(m.is_object() && m.contains("cases")) << "MANIFEST.json is not a {\"cases\": [..]}";
  const std::vector<BadCase> cases = manifestCases();
  EXPECT_GE(cases.size(), 40u);

  std::set<std::string> listedFiles;  // relative paths of files the manifest covers
  std::set<std::string> listedFolders;
  std::map<std::string, int> perFormat;
  for (const auto& c : cases) {
    EXPECT_FALSE(c.file.empty() || c.format.empty() || c.problem.empty() || c.expect.empty())
        << "incomplete manifest entry for '" << c.file << "'";
    ++perFormat[c.format];
    EXPECT_TRUE(fs::exists(badRoot() / c.file)) << c.file << " is listed but missing";
    if (fs::is_directory(badRoot() / c.file)) {
      listedFolders.insert(c.file + "/");
    } else {
      listedFiles.insert(c.file);
    }
    for (const auto& comp : c.companions) {
      EXPECT_TRUE(fs::is_regular_file(badRoot() / comp)) << comp << " is listed but missing";
      listedFiles.insert(comp);
    }
  }
  for (const auto& e : fs::recursive_directory_iterator(badRoot())) {
    if (!e.is_regular_file()) continue;
    const std::string rel = fs::relative(e.path(), badRoot()).generic_string();
    if (rel == "MANIFEST.json" || listedFiles.count(rel) != 0) continue;
    const bool inFolder = std::any_of(listedFolders.begin(), listedFolders.end(),
                                      [&](const std::string& f) { return rel.rfind(f, 0) == 0; });
    EXPECT_TRUE(inFolder) << rel << " is in tests/data/bad but not in MANIFEST.json";
  }
  std::string counts;
  for (const auto& [format, n] : perFormat) {
    counts += (counts.empty() ? "" : ", ") + format + " " + std::to_string(n);
  }
  std::printf("bad corpus: %zu cases (%s)\n", cases.size(), counts.c_str());
}

}  // namespace
}  // namespace tessera
