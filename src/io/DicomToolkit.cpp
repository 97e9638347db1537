#include "io/DicomToolkit.h"

#include <mutex>

#include <dcmtk/dcmdata/dcdict.h>
#include <dcmtk/dcmdata/dcrledrg.h>
#include <dcmtk/dcmdata/dcrleerg.h>
#include <dcmtk/dcmjpeg/djdecode.h>
#include <dcmtk/dcmjpls/djdecode.h>
#include <dcmtk/dcmjpls/djencode.h>
#include <dcmtk/oflog/oflog.h>

#include "tessera/core/Error.h"

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

std::string conditionText(const OFCondition& cond) {
  const char* t = cond.text();
  return t != nullptr ? t : "unknown DCMTK error";
}

}  // namespace tessera::io_detail
