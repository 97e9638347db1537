#pragma once
// HTJ2K (JPEG 2000 Part 15, PS3.5 A.4.11: transfer syntaxes
// 1.2.840.10008.1.2.4.201, .202 and .203) frames of a DICOM image, decoded by
// Debian's OpenJPH (libopenjph 0.9). Checked like a JPEG 2000 frame
// (Jpeg2000Frame.h: rows, columns, one greyscale component, at most Bits
// Allocated deep, and the sign Pixel Representation declares) before a
// sample is written.
//
// OpenJPH 0.9 is not safe on corrupt input by itself: a zero tile size
// divides by zero, and a code-block that claims more bytes than its tile-part
// holds makes it zero-fill past its buffer (precinct::parse, found by
// scripts/fuzz.sh; its own ojph_expand overflows on the same input), and
// Debian builds it with assertions that some corrupt packet headers fire
// (found by fuzz_htj2k). So the
// codestream's markers are walked here first and the stream OpenJPH reads is
// rebuilt: one tile-part per tile, each followed by guard bytes that no valid
// packet reaches, and a read that touches them is refused before OpenJPH can
// write anything; and OpenJPH runs in a child process, so that an abort there
// is an InputError here. Tiled codestreams are refused: OpenJPH 0.9 decodes
// those tiled in both directions wrongly (see Htj2kFrame.cpp).
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "io/Jpeg2000Frame.h"

namespace tessera::io_detail {

// The frame's samples as decodeJpeg2000Frame gives them (row by row, each
// Bits Allocated wide in host byte order). InputError "WHAT: ..." for a
// corrupt or truncated codestream or one that differs from `shape`.
std::vector<std::uint8_t> decodeHtj2kFrame(std::span<const std::uint8_t> codestream,
                                           const FrameShape& shape, const std::string& what);

}  // namespace tessera::io_detail
