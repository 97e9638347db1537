// libFuzzer target: readRawWithSidecar with a fuzzed JSON sidecar next to a
// fixed 512-byte data file (the seeds describe volumes that fit it).
#include <array>
#include <cstddef>
#include <cstdint>

#include "FuzzSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/PvmReader.h"

namespace {
const std::filesystem::path& rawFile() {
  static const std::filesystem::path file = tessera::fuzz::scratchDir() / "data.raw";
  return file;
}
}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  tessera::fuzz::initialize();
  std::array<std::uint8_t, 512> voxels{};
  for (std::size_t i = 0; i < voxels.size(); ++i) voxels[i] = static_cast<std::uint8_t>(i * 37);
  tessera::fuzz::writeBytes(rawFile(), voxels.data(), voxels.size());
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path sidecar = tessera::fuzz::scratchDir() / "data.raw.json";
  tessera::fuzz::writeBytes(sidecar, data, size);
  try {
    tessera::readRawWithSidecar(rawFile());
  } catch (const tessera::Error& e) {
    tessera::fuzz::rejected(e);
  }
  return 0;
}
