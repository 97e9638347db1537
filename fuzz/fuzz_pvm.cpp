// libFuzzer target: readPvm on a PVM/PVM2/PVM3 file or its DDS-compressed form.
#include <cstddef>
#include <cstdint>

#include "FuzzTarget.h"
#include "tessera/io/PvmReader.h"

void tessera::fuzz::fuzzOne(const std::uint8_t* data, std::size_t size) {
  readPvm(input("input.pvm", data, size));
}
