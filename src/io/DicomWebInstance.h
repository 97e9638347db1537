#pragma once
// One frame of a whole instance (a Part-10 file, as WADO-RS sends it with
// Accept: application/dicom): for archives that cannot send some frames on
// their own (Orthanc 1.10 answers HTTP 500 for single HTJ2K frames), the
// DICOMweb client retrieves the instance and cuts each frame out of it, in
// the bytes a frame request would have given, so that the same frame
// decoders (io/DicomWebFrame.h) decode it. The file is parsed by the basic
// reader's strict Part-10 parser (io/DicomBasicReader.cpp: every length
// checked, nesting bounded), which here accepts every syntax whose dataset
// is little endian, whatever this build's codecs decode.
#include <cstddef>
#include <string>
#include <vector>

#include "io/DicomSeries.h"
#include "tessera/io/ByteSource.h"

namespace tessera::io_detail {

struct InstanceFrame {
  std::string transferSyntax;    // the file's Transfer Syntax UID (0002,0010)
  std::vector<std::byte> bytes;  // native samples (little endian) or the codestream
};

// Frame `slice.frame` (of `slice.frames`) of `file`: for native pixel data
// its bytes (frameRange), for encapsulated data its fragments (PS3.5 A.4:
// one per frame, or as the Basic Offset Table divides them). InputError
// naming `file` for a file that is not Part-10, malformed, without Pixel
// Data, or whose frames cannot be told apart.
InstanceFrame instanceFrame(const ByteSource& file, const Slice& slice);

}  // namespace tessera::io_detail
