#pragma once
// JPEG 2000 (PS3.5 A.4.4: transfer syntaxes 1.2.840.10008.1.2.4.90 and .91)
// frames of a DICOM image, decoded by Debian's OpenJPEG (libopenjp2). HTJ2K
// (A.4.11: .201, .202, .203) is refused: on corrupt code-block data Debian
// 12's OpenJPH 0.9 writes past its buffers and its OpenJPEG 2.5.0 aborts on
// an assertion (a Part-15 stream inside a .90/.91 file is refused too). Each frame is checked
// against what the file declares (rows, columns, one greyscale component, at most the bits stored)
// before a sample is written, so that a frame's own header never sizes an allocation.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace tessera::io_detail {

// What the DICOM header says a frame holds.
struct FrameShape {
  int rows = 0;
  int columns = 0;
  int bitsAllocated = 16;  // 8 or 16: the width of each decoded sample
  int bitsStored = 16;
  int samplesPerPixel = 1;
};

// The frame's samples, row by row, each bitsAllocated
// wide in host byte order (a signed sample in two's complement), as uncompressed pixel data would
// hold them. InputError "WHAT: ..." for a corrupt or truncated codestream, or one whose size,
// components or precision differ from `shape` (more than one component is refused: not greyscale).
std::vector<std::uint8_t> decodeJpeg2000Frame(std::span<const std::uint8_t> codestream,
                                              const FrameShape& shape, const std::string& what);

}  // namespace tessera::io_detail
