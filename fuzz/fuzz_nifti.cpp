// libFuzzer target: readNifti on the bytes of a .nii file (gzip-compressed when they start
// with the gzip magic), parsed by the reader itself.
#include <cstddef>
#include <cstdint>

#include "FuzzSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/NiftiReader.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  tessera::fuzz::initialize();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    tessera::readNifti(tessera::fuzz::input("input.nii", data, size), tessera::fuzz::besideInput());
  } catch (const tessera::Error& e) {
    tessera::fuzz::rejected(e);
  }
  return 0;
}
