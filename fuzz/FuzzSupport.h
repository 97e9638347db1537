#pragma once
// What every fuzz target shares: a small host budget, so that a header
// claiming gigabytes is refused instead of allocated; the input as a memory
// byte source (the readers' own entry point, the one the browser uses), with
// a fixed 512-byte data file beside it for headers that name one; and a
// per-process scratch folder for the DICOM reader, which reads paths (the
// file name's extension picks nothing here; each target calls its reader
// directly).
//
// A target catches tessera::Error, the documented way to reject input. Any
// other exception escapes LLVMFuzzerTestOneInput, std::terminate aborts, and
// libFuzzer reports the input as a crash: readers must turn library errors
// (nlohmann::json, DCMTK, zlib) into InputError.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <span>
#include <vector>

#include "../tests/support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/io/ByteSource.h"

namespace tessera::fuzz {

// 64 MiB: far above what the seeds need, far below -rss_limit_mb.
constexpr std::uint64_t kFuzzHostBudget = 64ull << 20;

// The tests' temporary folder (tests/support/TestSupport.h), made once per
// process: removed when it exits normally; crashes leave it for inspection.
inline const std::filesystem::path& scratchDir() {
  static const test::TempDir dir;
  return dir.path();
}

inline void initialize() {
  HostBudget::global().setLimit(kFuzzHostBudget);
  scratchDir();
}

// Replaces `path` with exactly these bytes; aborts if it cannot (a broken
// harness must not look like a reader bug or, worse, like a clean run).
inline void writeBytes(const std::filesystem::path& path, const std::uint8_t* data,
                       std::size_t size) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr || (size > 0 && std::fwrite(data, 1, size, f) != size) || std::fclose(f) != 0) {
    std::fprintf(stderr, "fuzz harness: cannot write %s\n", path.c_str());
    std::abort();
  }
}

// The fuzzed bytes as a file named `name`, without a copy.
inline MemorySource input(const std::string& name, const std::uint8_t* data, std::size_t size) {
  return MemorySource(name, std::span(reinterpret_cast<const std::byte*>(data), size));
}

// The files beside the input: "data.raw", 512 bytes, for the headers that
// name a data file (.nhdr, .mhd, a JSON sidecar); the seeds' volumes fit it.
inline const MemoryFiles& besideInput() {
  static const MemoryFiles files = [] {
    std::vector<std::byte> voxels(512);
    for (std::size_t i = 0; i < voxels.size(); ++i) voxels[i] = static_cast<std::byte>(i * 37);
    MemoryFiles f;
    f.add("data.raw", std::move(voxels));
    return f;
  }();
  return files;
}

// Called with each clean rejection; TESSERA_FUZZ_VERBOSE=1 prints them (to
// check that seeds are accepted, or why an input is refused).
inline void rejected(const Error& e) {
  static const bool verbose = [] {
    const char* v = std::getenv("TESSERA_FUZZ_VERBOSE");
    return v != nullptr && v[0] == '1';
  }();
  if (verbose) std::fprintf(stderr, "rejected: %s\n", e.what());
}

}  // namespace tessera::fuzz
