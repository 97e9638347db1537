// libFuzzer target: readMetaImage on a .mha (header and data, raw or zlib, in one
// file) or a header naming "data.raw".
#include <cstddef>
#include <cstdint>

#include "FuzzSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/MetaImageReader.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  tessera::fuzz::initialize();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    tessera::readMetaImage(tessera::fuzz::input("input.mha", data, size),
                           tessera::fuzz::besideInput());
  } catch (const tessera::Error& e) {
    tessera::fuzz::rejected(e);
  }
  return 0;
}
