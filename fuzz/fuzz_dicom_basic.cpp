// libFuzzer target: the DICOM reader without DCMTK (io/DicomBasicReader.h),
// as the browser runs it: the fuzzed bytes are a dropped file in memory,
// read as a one-slice series (parser, slice checks, RLE decoder, voxel copy
// and rescale).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "FuzzSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/DicomBasicReader.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  tessera::fuzz::initialize();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  tessera::MemoryFiles files;
  files.add("drop/fuzzed.dcm",
            std::span<const std::byte>(reinterpret_cast<const std::byte*>(data), size));
  try {
    tessera::readDicomSeriesBasic(*files.open("drop/fuzzed.dcm"), files);
  } catch (const tessera::Error& e) {
    tessera::fuzz::rejected(e);
  }
  return 0;
}
