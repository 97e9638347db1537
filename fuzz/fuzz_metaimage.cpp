// libFuzzer target: readMetaImage on a .mha (header and data, raw or zlib, in one file).
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
  static const std::filesystem::path file = tessera::fuzz::scratchDir() / "input.mha";
  tessera::fuzz::writeBytes(file, data, size);
  try {
    tessera::readMetaImage(file);
  } catch (const tessera::Error& e) {
    tessera::fuzz::rejected(e);
  }
  return 0;
}
