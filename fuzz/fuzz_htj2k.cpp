// libFuzzer target: an HTJ2K codestream (io/Htj2kFrame.h) as a DICOM frame
// holds it, decoded by OpenJPH behind Tessera's marker walk and checks. The
// frame's declared shape is taken from the codestream's own SIZ marker (when
// it is small), so that fuzzing gets past the header checks into OpenJPH's
// packet parsing and HT block decoding.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "FuzzTarget.h"
#include "io/Htj2kFrame.h"

namespace {

std::uint32_t u32(const std::uint8_t* d) {
  return (std::uint32_t(d[0]) << 24) | (std::uint32_t(d[1]) << 16) | (std::uint32_t(d[2]) << 8) |
         d[3];
}

// ISO 15444-1 A.5.1: SIZ follows SOC; Xsiz at byte 8, Ysiz 12, XOsiz 16,
// YOsiz 20, Ssiz of the first component 42.
tessera::io_detail::FrameShape shapeOf(const std::uint8_t* d, std::size_t size) {
  tessera::io_detail::FrameShape shape{.rows = 32, .columns = 32, .bitsAllocated = 16};
  if (size < 43) return shape;
  const std::int64_t w = std::int64_t(u32(d + 8)) - u32(d + 16);
  const std::int64_t h = std::int64_t(u32(d + 12)) - u32(d + 20);
  if (w > 0 && h > 0 && w <= 4096 && h <= 4096 && w * h <= (1 << 20)) {
    shape.columns = static_cast<int>(w);
    shape.rows = static_cast<int>(h);
  }
  const int bits = (d[42] & 0x7f) + 1;
  shape.bitsAllocated = bits <= 8 ? 8 : 16;
  shape.bitsStored = bits;
  shape.isSigned = (d[42] & 0x80) != 0;
  return shape;
}

}  // namespace

void tessera::fuzz::fuzzOne(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> stream(data, size);
  const io_detail::FrameShape shape = shapeOf(data, size);
  io_detail::decodeHtj2kFrame(stream, shape, "fuzzed.dcm frame 1");
}
