// libFuzzer target: what a DICOMweb archive answers (io/DicomWebParts.h,
// io/DicomWebFrame.h). The input is a Content-Type line, then the body: the
// body is split as a multipart/related answer and each part decoded as a
// 64x64 signed 16-bit frame (the seeds: pydicom's MR_small, encoded) in the
// transfer syntax it names (DCMTK's codecs and OpenJPEG behind the checks of
// a WADO-RS read), and read as a DICOM JSON answer whose datasets go
// through the series code's slice header.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "FuzzTarget.h"
#include "io/DicomWebFrame.h"
#include "io/DicomWebParts.h"

void tessera::fuzz::fuzzOne(const std::uint8_t* data, std::size_t size) {
  const std::uint8_t* eol = std::find(data, data + size, std::uint8_t{'\n'});
  const std::string contentType(reinterpret_cast<const char*>(data), std::size_t(eol - data));
  const std::uint8_t* start = eol == data + size ? eol : eol + 1;
  const std::span<const std::byte> body(reinterpret_cast<const std::byte*>(start),
                                        std::size_t(data + size - start));
  io_detail::Slice slice;
  slice.rows = 64;
  slice.columns = 64;
  slice.bitsAllocated = 16;
  slice.bitsStored = 16;
  slice.isSigned = true;
  slice.highBit = 15;
  slice.photometric = "MONOCHROME2";
  try {
    for (const auto& part : io_detail::parseMultipart(contentType, body, "fuzzed", 4)) {
      try {
        io_detail::decodeWebFrame(slice, io_detail::frameTransferSyntax(part.contentType),
                                  part.body, "fuzzed frame");
      } catch (const Error&) {
        // rejected: the next part
      }
    }
  } catch (const Error&) {
    // rejected: the JSON reading still runs
  }
  const nlohmann::json datasets = io_detail::parseDicomJson(body, "fuzzed");
  for (const nlohmann::json& d : datasets) {
    const io_detail::DicomJsonAttributes a(d);
    (void)io_detail::sliceHeader("fuzzed", a);
  }
}
