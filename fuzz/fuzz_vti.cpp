// libFuzzer target: readVti on a VTK XML ImageData file.
#include <cstddef>
#include <cstdint>

#include "FuzzTarget.h"
#include "tessera/io/VtiReader.h"

void tessera::fuzz::fuzzOne(const std::uint8_t* data, std::size_t size) {
  readVti(input("input.vti", data, size));
}
