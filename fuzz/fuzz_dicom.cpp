// libFuzzer target: readDicomSeries on a folder holding one fuzzed file, so
// that the folder scan, DCMTK's parser and the slice checks all see it.
#include <cstddef>
#include <cstdint>

#include "FuzzSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/DicomSeriesReader.h"

namespace {
const std::filesystem::path& seriesFolder() {
  static const std::filesystem::path folder = tessera::fuzz::scratchDir() / "series";
  return folder;
}
}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  tessera::fuzz::initialize();
  std::filesystem::create_directories(seriesFolder());
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path file = seriesFolder() / "slice.dcm";
  tessera::fuzz::writeBytes(file, data, size);
  try {
    tessera::readDicomSeries(seriesFolder());
  } catch (const tessera::Error& e) {
    tessera::fuzz::rejected(e);
  }
  return 0;
}
