// libFuzzer target: readMetaImage on a .mha (header and data, raw or zlib, in one
// file) or a header naming "data.raw".
#include <cstddef>
#include <cstdint>

#include "FuzzTarget.h"
#include "tessera/io/MetaImageReader.h"

void tessera::fuzz::fuzzOne(const std::uint8_t* data, std::size_t size) {
  readMetaImage(input("input.mha", data, size), besideInput());
}
