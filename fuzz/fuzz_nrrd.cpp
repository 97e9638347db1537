// libFuzzer target: readNrrd on a .nrrd, or a detached header naming "data.raw".
#include <cstddef>
#include <cstdint>

#include "FuzzTarget.h"
#include "tessera/io/NrrdReader.h"

void tessera::fuzz::fuzzOne(const std::uint8_t* data, std::size_t size) {
  readNrrd(input("input.nrrd", data, size), besideInput());
}
