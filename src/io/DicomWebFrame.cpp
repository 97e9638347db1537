#include "io/DicomWebFrame.h"

#include <cstring>
#include <memory>

#include "io/DicomToolkit.h"
#include "io/Jpeg2000Frame.h"
#include "tessera/core/Error.h"

#include <dcmtk/dcmdata/dcdatset.h>
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcpixel.h>
#include <dcmtk/dcmdata/dcpixseq.h>
#include <dcmtk/dcmdata/dcpxitem.h>

namespace tessera::io_detail {

namespace {

std::uint64_t frameBytes(const Slice& s) {
  return static_cast<std::uint64_t>(s.rows) * static_cast<std::uint64_t>(s.columns) *
         static_cast<std::uint64_t>(s.bitsAllocated / 8);
}

std::vector<std::byte> copyOf(const void* p, std::size_t n) {
  std::vector<std::byte> out(n);
  if (n > 0) std::memcpy(out.data(), p, n);
  return out;
}

// Uncompressed: little endian as sent; big endian swapped to host order.
std::vector<std::byte> uncompressed(const Slice& s, std::span<const std::byte> frame,
                                    bool bigEndian) {
  std::vector<std::byte> out = copyOf(frame.data(), frame.size());
  if (bigEndian && s.bitsAllocated == 16) {
    for (std::size_t i = 0; i + 1 < out.size(); i += 2) std::swap(out[i], out[i + 1]);
  }
  return out;
}

// A JPEG, JPEG-LS or RLE frame as the one fragment of a dataset's
// encapsulated pixel data (PS3.5 A.4), decoded by DCMTK's codecs.
std::vector<std::byte> throughDcmtk(const Slice& s, E_TransferSyntax xfer,
                                    std::span<const std::byte> frame, const std::string& what) {
  initDicomToolkit();
  if (!canDecodePixels(xfer)) throw InputError(undecodableSyntaxMessage(what, xfer));
  checkJpegFragment(xfer, {reinterpret_cast<const std::uint8_t*>(frame.data()), frame.size()},
                    what);
  DcmDataset ds;
  ds.putAndInsertUint16(DCM_Rows, static_cast<Uint16>(s.rows));
  ds.putAndInsertUint16(DCM_Columns, static_cast<Uint16>(s.columns));
  ds.putAndInsertUint16(DCM_BitsAllocated, static_cast<Uint16>(s.bitsAllocated));
  ds.putAndInsertUint16(DCM_BitsStored, static_cast<Uint16>(s.bitsStored));
  ds.putAndInsertUint16(DCM_HighBit, static_cast<Uint16>(s.highBit));
  ds.putAndInsertUint16(DCM_PixelRepresentation, s.isSigned ? 1 : 0);
  ds.putAndInsertUint16(DCM_SamplesPerPixel, static_cast<Uint16>(s.samplesPerPixel));
  ds.putAndInsertString(DCM_PhotometricInterpretation,
                        s.photometric.empty() ? "MONOCHROME2" : s.photometric.c_str());
  auto sequence = std::make_unique<DcmPixelSequence>(DCM_PixelSequenceTag);
  sequence->insert(new DcmPixelItem(DCM_PixelItemTag));  // empty Basic Offset Table
  auto* fragment = new DcmPixelItem(DCM_PixelItemTag);
  // Fragments have even length (PS3.5 A.4); the codecs ignore the pad byte.
  std::vector<Uint8> even(frame.size() + (frame.size() % 2));
  if (!frame.empty()) std::memcpy(even.data(), frame.data(), frame.size());
  fragment->putUint8Array(even.data(), static_cast<unsigned long>(even.size()));
  sequence->insert(fragment);
  auto* pixels = new DcmPixelData(DCM_PixelData);
  pixels->putOriginalRepresentation(xfer, nullptr, sequence.release());
  ds.insert(pixels, true);
  const OFCondition c = ds.chooseRepresentation(EXS_LittleEndianExplicit, nullptr);
  if (c.bad() || !ds.canWriteXfer(EXS_LittleEndianExplicit)) {
    throw InputError(what + ": the " + transferSyntaxText(xfer) +
                     " frame cannot be decoded (DCMTK: " + conditionText(c) +
                     "; corrupt or truncated?)");
  }
  DcmElement* elem = nullptr;
  if (ds.findAndGetElement(DCM_PixelData, elem).bad() || elem == nullptr) {
    throw InputError(what + ": the decoded frame has no pixel data");
  }
  const std::size_t length = elem->getLength();
  if (s.bitsAllocated == 8) {
    Uint8* p = nullptr;
    if (elem->getUint8Array(p).bad() || p == nullptr) {
      throw InputError(what + ": the decoded frame cannot be read");
    }
    return copyOf(p, length);
  }
  Uint16* p = nullptr;
  if (elem->getUint16Array(p).bad() || p == nullptr) {
    throw InputError(what + ": the decoded frame cannot be read");
  }
  return copyOf(p, length);
}

// JPEG 2000 through OpenJPEG; HTJ2K (`htj2k`) through OpenJPH's checks.
std::vector<std::byte> throughOpenJpeg(const Slice& s, std::span<const std::byte> frame,
                                       const std::string& what, bool htj2k) {
  const FrameShape shape{s.rows,       s.columns,         s.bitsAllocated,
                         s.bitsStored, s.samplesPerPixel, s.isSigned};
  const std::span<const std::uint8_t> bytes(reinterpret_cast<const std::uint8_t*>(frame.data()),
                                            frame.size());
  const std::vector<std::uint8_t> samples =
      htj2k ? decodeHtj2kSyntaxFrame(bytes, shape, what) : decodeJpeg2000Frame(bytes, shape, what);
  return copyOf(samples.data(), samples.size());
}

}  // namespace

std::string webFrameSyntaxesText() {
  return "uncompressed, JPEG baseline/extended/lossless, JPEG-LS, RLE, JPEG 2000 and HTJ2K";
}

std::vector<std::byte> decodeWebFrame(const Slice& s, const std::string& transferSyntax,
                                      std::span<const std::byte> frame, const std::string& what) {
  if (s.bitsAllocated != 8 && s.bitsAllocated != 16) {
    throw InputError(what + ": Bits Allocated is " + std::to_string(s.bitsAllocated) +
                     ", expected 8 or 16");
  }
  std::vector<std::byte> out;
  if (transferSyntax == "1.2.840.10008.1.2.1" || transferSyntax == "1.2.840.10008.1.2") {
    out = uncompressed(s, frame, false);
  } else if (transferSyntax == "1.2.840.10008.1.2.2") {
    out = uncompressed(s, frame, true);
  } else if (transferSyntax == "1.2.840.10008.1.2.4.90" ||
             transferSyntax == "1.2.840.10008.1.2.4.91") {
    out = throughOpenJpeg(s, frame, what, false);
  } else if (transferSyntax == "1.2.840.10008.1.2.4.201" ||  // HTJ2K lossless
             transferSyntax == "1.2.840.10008.1.2.4.202" ||  // HTJ2K RPCL lossless
             transferSyntax == "1.2.840.10008.1.2.4.203") {  // HTJ2K
    out = throughOpenJpeg(s, frame, what, true);
  } else {
    const DcmXfer x(transferSyntax.c_str());
    if (x.getXfer() == EXS_Unknown || !x.isEncapsulated()) {
      throw InputError(what + ": the frame's transfer syntax '" + transferSyntax.substr(0, 64) +
                       "' is not one this build decodes (" + webFrameSyntaxesText() + ")");
    }
    out = throughDcmtk(s, x.getXfer(), frame, what);
  }
  // As a file's pixel data: Rows x Columns samples, padding below a frame.
  const std::uint64_t expected = frameBytes(s);
  if (out.size() < expected || (out.size() > expected + 1 && out.size() >= 2 * expected)) {
    throw InputError(what + ": the frame decodes to " + std::to_string(out.size()) +
                     " bytes, but " + std::to_string(s.columns) + "x" + std::to_string(s.rows) +
                     " pixels x " + std::to_string(s.bitsAllocated / 8) +
                     " bytes = " + std::to_string(expected) + " bytes");
  }
  return out;
}

}  // namespace tessera::io_detail
