#pragma once
// JPEG 2000 (PS3.5 A.4.4: transfer syntaxes 1.2.840.10008.1.2.4.90 and .91)
// frames of a DICOM image, decoded by Debian's OpenJPEG (libopenjp2). HTJ2K
// (A.4.11: .201, .202, .203) is Htj2kFrame.h's: Debian 12's OpenJPEG 2.5.0
// aborts on an assertion on corrupt HTJ2K data, so a Part-15 stream inside a
// .90/.91 file goes there too. Each frame is checked
// against what the file declares (rows, columns, one greyscale component, at most the bits stored)
// before a sample is written, so that a frame's own header never sizes an allocation.
#include <cstdint>
#include <optional>
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
  // Pixel Representation (1: signed), checked where the codec records it.
  std::optional<bool> isSigned;
};

// The frame's samples, row by row, each bitsAllocated
// wide in host byte order (a signed sample in two's complement), as uncompressed pixel data would
// hold them. InputError "WHAT: ..." for a corrupt or truncated codestream, or one whose size,
// components or precision differ from `shape` (more than one component is refused: not greyscale).
std::vector<std::uint8_t> decodeJpeg2000Frame(std::span<const std::uint8_t> codestream,
                                              const FrameShape& shape, const std::string& what);

// A frame of a file that declares HTJ2K (.201, .202, .203): a plain Part-1
// codestream (SOC without a CAP marker) goes to decodeJpeg2000Frame, anything
// else to decodeHtj2kFrame (Htj2kFrame.h), whose checks name what is wrong.
std::vector<std::uint8_t> decodeHtj2kSyntaxFrame(std::span<const std::uint8_t> codestream,
                                                 const FrameShape& shape, const std::string& what);

// What both codecs share. checkFrameHeader: the frame's header against
// `shape` (one greyscale component of Columns x Rows, not subsampled, at most
// Bits Allocated deep), an InputError naming `codec` otherwise.
void checkFrameHeader(const FrameShape& shape, const std::string& what, const std::string& codec,
                      long long width, long long height, unsigned components, unsigned precision,
                      bool subsampled);
// Room for the frame's samples (Bits Allocated 8 or 16, else an InputError).
std::vector<std::uint8_t> frameSamples(const FrameShape& shape, const std::string& what);
// Sample `index` as uncompressed pixel data holds it: the low `bits` bits of
// its two's complement, host byte order.
void putFrameSample(std::vector<std::uint8_t>& out, std::size_t index, std::int32_t value,
                    int bits);

}  // namespace tessera::io_detail
