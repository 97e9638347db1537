// libFuzzer target: readRawWithSidecar with a fuzzed JSON sidecar
// "data.raw.json" next to the fixed 512-byte "data.raw" (the seeds describe
// volumes that fit it), read from the raw file as the CLI is given it.
#include <cstddef>
#include <cstdint>

#include "FuzzTarget.h"
#include "tessera/io/RawSidecarReader.h"

void tessera::fuzz::fuzzOne(const std::uint8_t* data, std::size_t size) {
  MemoryFiles files = besideInput();
  files.add("data.raw.json", std::span(reinterpret_cast<const std::byte*>(data), size));
  readRawWithSidecar(*files.open("data.raw"), files);
}
