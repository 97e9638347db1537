#include "io/DicomToolkit.h"

#include <mutex>

#include <dcmtk/dcmdata/dccodec.h>
#include <dcmtk/dcmdata/dcdatset.h>
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcdict.h>
#include <dcmtk/dcmdata/dcpixel.h>
#include <dcmtk/dcmdata/dcpixseq.h>
#include <dcmtk/dcmdata/dcpxitem.h>
#include <dcmtk/dcmdata/dcrledrg.h>
#include <dcmtk/dcmdata/dcrleerg.h>
#include <dcmtk/dcmjpeg/djdecode.h>
#include <dcmtk/dcmjpls/djdecode.h>
#include <dcmtk/dcmjpls/djencode.h>
#include <dcmtk/oflog/oflog.h>

#include "tessera/core/Error.h"
#include "tessera/io/DicomDecoder.h"
#include "tessera/io/DicomSeriesReader.h"

namespace tessera::io_detail {

void initDicomToolkit() {
  static std::once_flag once;
  std::call_once(once, [] {
    // DCMTK logs parse warnings to stderr; every problem that matters to us
    // becomes an InputError with the file name instead.
    OFLog::configure(OFLogger::FATAL_LOG_LEVEL);
    DJDecoderRegistration::registerCodecs();
    DJLSDecoderRegistration::registerCodecs();
    // The "raw" JPEG-LS encoder compresses the stored bits as they are. The
    // default "cooked" one renders pixels through dcmimgle first, which in
    // DCMTK 3.6.7 makes non-deterministic, sometimes undecodable streams for
    // signed 16-bit noise (seen in DicomSeriesReader.CompressedSeriesReadBackExactly).
    DJLSEncoderRegistration::registerCodecs(0, 0, 0, 0, /*preferCookedEncoding=*/OFFalse);
    DcmRLEDecoderRegistration::registerCodecs();
    DcmRLEEncoderRegistration::registerCodecs();
  });
  if (!dcmDataDict.isDictionaryLoaded()) {
    throw Error("DCMTK's data dictionary is not loaded (expected " DCM_DICT_DEFAULT_PATH
                "); install DCMTK's dictionary or point DCMDICTPATH at dicom.dic");
  }
}

std::string transferSyntaxText(E_TransferSyntax xfer) {
  const DcmXfer x(xfer);
  std::string s = x.getXferName() != nullptr ? x.getXferName() : "unknown transfer syntax";
  const char* id = x.getXferID();
  if (id != nullptr && *id != '\0') s += std::string(" (") + id + ")";
  return s;
}

bool canDecodePixels(E_TransferSyntax xfer) {
  return !DcmXfer(xfer).isEncapsulated() ||
         DcmCodecList::canChangeCoding(xfer, EXS_LittleEndianExplicit);
}

std::string undecodableSyntaxMessage(const std::string& file, E_TransferSyntax xfer) {
  const DcmXfer x(xfer);
  const std::string uid = x.getXferID() != nullptr ? x.getXferID() : "unknown";
  // Free DCMTK has no JPEG 2000 codec (dcmdjpeg decodes JPEG 1992 only; the
  // JPEG 2000 module is commercial); GDCM decodes it through OpenJPEG.
  const bool j2k = xfer == EXS_JPEG2000LosslessOnly || xfer == EXS_JPEG2000 ||
                   xfer == EXS_JPEG2000MulticomponentLosslessOnly ||
                   xfer == EXS_JPEG2000Multicomponent;
  const std::string what = j2k ? "JPEG 2000 (transfer syntax UID " + uid + ")"
                               : "transfer syntax " + transferSyntaxText(xfer);
  return file + ": " + what +
         " is not supported by this build (it decodes uncompressed, deflate, JPEG "
         "baseline/extended/lossless, JPEG-LS and RLE); convert it with e.g. `gdcmconv --raw " +
         file + " out.dcm` (GDCM" +
         (j2k ? ", which decodes JPEG 2000; DCMTK's dcmdjpeg does not)" : ")");
}

namespace {

bool isJpeg1992(E_TransferSyntax xfer) {
  return xfer >= EXS_JPEGProcess1 && xfer <= EXS_JPEGProcess14SV1;
}

// Where dcmjpeg's precision scan goes from the marker at `offset`: the next
// offset, or npos where the scan ends (a frame header found, or a byte
// sequence it gives up on). `stalls` is set at a TEM marker, which it
// neither skips nor accepts.
constexpr std::size_t kScanEnds = static_cast<std::size_t>(-1);

std::size_t nextScanOffset(std::span<const std::uint8_t> b, std::size_t offset, bool& stalls) {
  const unsigned marker = (unsigned{b[offset]} << 8) | b[offset + 1];
  const auto segment = [&] {
    return offset + ((unsigned{b[offset + 2]} << 8) | b[offset + 3]) + 2;
  };
  if (marker == 0xFF01) {
    stalls = true;
    return kScanEnds;
  }
  const bool frameHeader = marker >= 0xFFC0 && marker <= 0xFFCF && marker != 0xFFC4 &&
                           marker != 0xFFC8 && marker != 0xFFCC;
  if (frameHeader) return kScanEnds;
  if (marker == 0xFFC4 || marker == 0xFFC8 || marker == 0xFFCC) return segment();
  if (marker >= 0xFFD0 && marker <= 0xFFD9) return offset + 2;  // RSTn, SOI, EOI
  if (marker >= 0xFFDA && marker <= 0xFFFE) return segment();
  if (marker == 0xFFFF) return offset + 1;  // fill byte
  if (b[offset] == 0xFF && b[offset + 1] > 0x02 && b[offset + 1] <= 0xBF) return offset + 2;
  return kScanEnds;
}

}  // namespace

void checkJpegFragment(E_TransferSyntax xfer, std::span<const std::uint8_t> fragment,
                       const std::string& what) {
  if (!isJpeg1992(xfer)) return;
  bool stalls = false;
  for (std::size_t offset = 0; offset != kScanEnds && offset + 4 < fragment.size();) {
    const std::size_t at = offset;
    offset = nextScanOffset(fragment, offset, stalls);
    if (stalls) {
      throw InputError(what + ": the JPEG frame has a TEM marker (FF01) at byte " +
                       std::to_string(at) +
                       " before its frame header, which DCMTK's JPEG decoder cannot pass "
                       "(corrupt frame?)");
    }
  }
}

void checkJpegFragments(DcmDataset& ds, const std::string& what) {
  const E_TransferSyntax xfer = ds.getOriginalXfer();
  if (!isJpeg1992(xfer)) return;
  DcmElement* elem = nullptr;
  if (ds.findAndGetElement(DCM_PixelData, elem).bad() || elem == nullptr) return;
  auto* pixels = dynamic_cast<DcmPixelData*>(elem);
  DcmPixelSequence* sequence = nullptr;
  if (pixels == nullptr || pixels->getEncapsulatedRepresentation(xfer, nullptr, sequence).bad() ||
      sequence == nullptr) {
    return;  // DCMTK reports what is wrong when it decodes
  }
  for (unsigned long i = 1; i < sequence->card(); ++i) {  // item 0: the offset table
    DcmPixelItem* item = nullptr;
    Uint8* data = nullptr;
    if (sequence->getItem(item, i).bad() || item == nullptr || item->getUint8Array(data).bad() ||
        data == nullptr) {
      continue;
    }
    checkJpegFragment(xfer, {data, item->getLength()},
                      what + " (fragment " + std::to_string(i) + ")");
  }
}

std::string conditionText(const OFCondition& cond) {
  const char* t = cond.text();
  return t != nullptr ? t : "unknown DCMTK error";
}

}  // namespace tessera::io_detail

namespace tessera {

namespace {
// DCMTK's series reader behind the DicomDecoder interface: every syntax its
// registered codecs decode, from files on disk (it opens them itself).
class DcmtkDicomDecoder final : public DicomDecoder {
 public:
  std::string name() const override { return "DCMTK"; }
  bool canDecode(std::string_view uid) const override {
    const DcmXfer x(std::string(uid).c_str());
    if (x.getXfer() == EXS_Unknown) return false;
    io_detail::initDicomToolkit();
    return io_detail::canDecodePixels(x.getXfer());
  }
  bool canRead(const FileSet& files) const override { return files.onDisk(); }
  std::string decodes() const override {
    return "uncompressed, deflate, JPEG baseline/extended/lossless, JPEG-LS, RLE";
  }
  Volume read(const ByteSource& named, const FileSet& files,
              const std::string& seriesUid) const override {
    if (!files.onDisk()) {
      throw InputError(named.name() + ": DCMTK reads DICOM files on disk only");
    }
    return readDicomSeries(named.name(), seriesUid);
  }
  Volume readFolder(const std::filesystem::path& folderOrFile,
                    const std::string& seriesUid) const override {
    return readDicomSeries(folderOrFile, seriesUid);
  }
};
}  // namespace

const DicomDecoder& dcmtkDicomDecoder() {
  static const DcmtkDicomDecoder decoder;
  return decoder;
}

}  // namespace tessera
