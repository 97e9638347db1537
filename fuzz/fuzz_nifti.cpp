// libFuzzer target: readNifti on one .nii file, or .nii.gz when the bytes
// start with the gzip magic (nifticlib picks gzip by the name).
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
  static const std::filesystem::path plain = tessera::fuzz::scratchDir() / "input.nii";
  static const std::filesystem::path gzip = tessera::fuzz::scratchDir() / "input.nii.gz";
  const bool gzipped = size >= 2 && data[0] == 0x1f && data[1] == 0x8b;
  const std::filesystem::path& file = gzipped ? gzip : plain;
  tessera::fuzz::writeBytes(file, data, size);
  try {
    tessera::readNifti(file);
  } catch (const tessera::Error& e) {
    tessera::fuzz::rejected(e);
  }
  return 0;
}
