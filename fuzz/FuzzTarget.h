#pragma once
// The libFuzzer entry points, the same for every target: a target is one
// .cpp that includes this header once and defines tessera::fuzz::fuzzOne,
// which hands the input to the code under test. initialize() runs first; a
// tessera::Error from fuzzOne is a clean rejection (see FuzzSupport.h), any
// other exception a crash.
#include <cstddef>
#include <cstdint>

#include "FuzzSupport.h"
#include "tessera/core/Error.h"

namespace tessera::fuzz {

void fuzzOne(const std::uint8_t* data, std::size_t size);

}  // namespace tessera::fuzz

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  tessera::fuzz::initialize();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    tessera::fuzz::fuzzOne(data, size);
  } catch (const tessera::Error& e) {
    tessera::fuzz::rejected(e);
  }
  return 0;
}
