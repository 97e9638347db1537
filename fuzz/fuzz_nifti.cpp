// libFuzzer target: readNifti on the bytes of a .nii file (gzip-compressed when they start
// with the gzip magic), parsed by the reader itself.
#include <cstddef>
#include <cstdint>

#include "FuzzTarget.h"
#include "tessera/io/NiftiReader.h"

void tessera::fuzz::fuzzOne(const std::uint8_t* data, std::size_t size) {
  readNifti(input("input.nii", data, size), besideInput());
}
