#pragma once
// The DCMTK setup shared by the DICOM series reader and writer: one-time
// process setup (quiet logging, codecs registered, data dictionary present)
// and the names users see for transfer syntaxes and DCMTK errors.
#include <cstdint>
#include <span>
#include <string>

#include <dcmtk/config/osconfig.h>  // must come before any other DCMTK header
#include <dcmtk/dcmdata/dcxfer.h>
#include <dcmtk/ofstd/ofcond.h>

class DcmDataset;

namespace tessera::io_detail {

// Idempotent and thread-safe. Silences DCMTK's logger (our errors carry the
// message instead), registers the JPEG, JPEG-LS and RLE decoders and the
// JPEG-LS and RLE encoders, and throws Error when DCMTK's data dictionary is
// missing (implicit-VR files cannot be parsed without it).
void initDicomToolkit();

// "JPEG 2000 Image Compression (Lossless Only) (1.2.840.10008.1.2.4.90)"
std::string transferSyntaxText(E_TransferSyntax xfer);

// Whether the registered codecs can decode pixel data stored in `xfer` (true
// for every native and deflated syntax).
bool canDecodePixels(E_TransferSyntax xfer);

// One line for a file whose pixel data no registered codec decodes, e.g.
// "scan.dcm: JPEG 2000 (transfer syntax UID 1.2.840.10008.1.2.4.90) is not
// supported by this build; convert it with e.g. `gdcmconv --raw ...`".
std::string undecodableSyntaxMessage(const std::string& file, E_TransferSyntax xfer);

// Throws InputError naming `what` when DCMTK's JPEG decoder would never
// return on `fragment`, the first bytes of a JPEG 1992 frame (`xfer` one of
// the JPEG processes; other syntaxes pass): before decoding, dcmjpeg 3.6.7
// walks the markers for the frame header's precision and does not advance
// past a TEM marker (FF01) met before it (a fuzzed DICOMweb frame hung there).
void checkJpegFragment(E_TransferSyntax xfer, std::span<const std::uint8_t> fragment,
                       const std::string& what);

// The same for each fragment of a dataset's encapsulated pixel data.
void checkJpegFragments(DcmDataset& ds, const std::string& what);

// DCMTK's text for a failed condition, e.g. "I/O suspension or premature end of stream".
std::string conditionText(const OFCondition& cond);

}  // namespace tessera::io_detail
