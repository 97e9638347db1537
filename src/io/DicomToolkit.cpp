#include "io/DicomToolkit.h"

#include <mutex>

#include <dcmtk/dcmdata/dccodec.h>
#include <dcmtk/dcmdata/dcdict.h>
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
