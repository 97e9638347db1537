// libFuzzer target: readDicomSeries on a folder holding one fuzzed file, so
// that the folder scan, DCMTK's parser and the slice checks all see it.
#include <cstddef>
#include <cstdint>

#include "FuzzTarget.h"
#include "tessera/io/DicomSeriesReader.h"

namespace {
// Made on first use, after initialize() has set up the scratch folder.
const std::filesystem::path& seriesFolder() {
  static const std::filesystem::path folder = [] {
    const std::filesystem::path f = tessera::fuzz::scratchDir() / "series";
    std::filesystem::create_directories(f);
    return f;
  }();
  return folder;
}
}  // namespace

void tessera::fuzz::fuzzOne(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path file = seriesFolder() / "slice.dcm";
  writeBytes(file, data, size);
  readDicomSeries(seriesFolder());
}
