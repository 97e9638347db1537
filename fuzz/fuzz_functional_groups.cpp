// libFuzzer target: the functional-group walk of multi-frame objects
// (io/DicomMultiFrame.cpp, framesOf). The input is a DICOM JSON answer (PS3.18
// F.2, as WADO-RS metadata gives a series' headers); each dataset's header is
// read by the series code (sliceHeader) and split into frames: an enhanced
// object's Shared and Per-frame Functional Groups (Pixel Measures, Plane
// Orientation and Position, Pixel Value Transformation, Frame VOI LUT, Frame
// Content's stacks), a classic one's Grid Frame Offset Vector or step, NM's
// Detector Information Sequence, and Number of Frames against all of them.
// The seeds (scripts/make_bad_corpus.py) are such headers: one stack, two
// stacks, classic RT Dose and NM.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <utility>

#include "FuzzTarget.h"
#include "io/DicomSeries.h"
#include "io/DicomWebParts.h"

void tessera::fuzz::fuzzOne(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::byte> body(reinterpret_cast<const std::byte*>(data), size);
  const nlohmann::json datasets = io_detail::parseDicomJson(body, "fuzzed");
  for (const nlohmann::json& d : datasets) {
    const io_detail::DicomJsonAttributes a(d);
    io_detail::Slice header = io_detail::sliceHeader("fuzzed", a);
    for (const io_detail::Slice& frame : io_detail::framesOf(std::move(header), a)) {
      (void)io_detail::sliceName(frame);
    }
  }
}
