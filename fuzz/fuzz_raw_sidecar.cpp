// libFuzzer target: readRawWithSidecar with a fuzzed JSON sidecar
// "data.raw.json" next to the fixed 512-byte "data.raw" (the seeds describe
// volumes that fit it), read from the raw file as the CLI is given it.
#include <cstddef>
#include <cstdint>

#include "FuzzSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/RawSidecarReader.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  tessera::fuzz::initialize();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  tessera::MemoryFiles files = tessera::fuzz::besideInput();
  files.add("data.raw.json", std::span(reinterpret_cast<const std::byte*>(data), size));
  try {
    tessera::readRawWithSidecar(*files.open("data.raw"), files);
  } catch (const tessera::Error& e) {
    tessera::fuzz::rejected(e);
  }
  return 0;
}
