#pragma once
// One frame as WADO-RS sends it (the bytes of one multipart part, in the
// transfer syntax the part names), decoded to the samples storePixels
// takes: uncompressed frames as they are, JPEG baseline/extended/lossless,
// JPEG-LS and RLE by DCMTK's registered codecs (the frame wrapped as the one
// fragment of encapsulated pixel data in memory, as a file would hold it),
// JPEG 2000 by OpenJPEG (io/Jpeg2000Frame.h). The decoded frame is checked
// against the slice's rows x columns x bits before it is accepted.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "io/DicomSeries.h"

namespace tessera::io_detail {

// Samples of `slice`'s frame (8-bit, or 16-bit in host byte order), at
// least rows x columns of them. InputError "WHAT: ..." naming the syntax for
// a syntax no codec of this build decodes, a corrupt or truncated frame, or
// one of another size than the slice declares.
std::vector<std::byte> decodeWebFrame(const Slice& slice, const std::string& transferSyntax,
                                      std::span<const std::byte> frame, const std::string& what);

// The transfer syntaxes decodeWebFrame decodes, for messages.
std::string webFrameSyntaxesText();

}  // namespace tessera::io_detail
