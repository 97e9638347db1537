// libFuzzer target: the DICOM reader without DCMTK (io/DicomBasicReader.h),
// as the browser runs it: the fuzzed bytes are a dropped file in memory,
// read as a one-slice series (parser, slice checks, RLE decoder, voxel copy
// and rescale).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "FuzzTarget.h"
#include "tessera/io/DicomBasicReader.h"

void tessera::fuzz::fuzzOne(const std::uint8_t* data, std::size_t size) {
  MemoryFiles files;
  files.add("drop/fuzzed.dcm",
            std::span<const std::byte>(reinterpret_cast<const std::byte*>(data), size));
  readDicomSeriesBasic(*files.open("drop/fuzzed.dcm"), files);
}
