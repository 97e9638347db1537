#pragma once
// One interface over the two DICOM readers: DCMTK's (DicomSeriesReader.h:
// every transfer syntax its codecs decode, files on disk) and the reader
// without DCMTK (DicomBasicReader.h: uncompressed and RLE, files on disk or
// in memory). readVolume asks the ranked list for the first decoder that
// decodes every transfer syntax of the files it was given and can read where
// they are; the native build ranks DCMTK first, the browser build has only
// the basic reader. Both assemble the series with the same code
// (io/DicomSeries.cpp), so a series both decode gives the same volume.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "tessera/core/Volume.h"
#include "tessera/io/ByteSource.h"

namespace tessera {

class DicomDecoder {
 public:
  virtual ~DicomDecoder() = default;
  // "DCMTK", "basic": for the table and messages.
  virtual std::string name() const = 0;
  // Whether it decodes pixel data stored in this transfer syntax.
  virtual bool canDecode(std::string_view transferSyntaxUid) const = 0;
  // Whether it reads files held by `files` (DCMTK reads files on disk only).
  virtual bool canRead(const FileSet& files) const = 0;
  // Short text for the table: "uncompressed, RLE".
  virtual std::string decodes() const = 0;
  // The series of `named` (or `seriesUid`), from the files beside it.
  virtual Volume read(const ByteSource& named, const FileSet& files,
                      const std::string& seriesUid) const = 0;
  // A folder (or one file and its series) on disk.
  virtual Volume readFolder(const std::filesystem::path& folderOrFile,
                            const std::string& seriesUid) const = 0;
};

// The decoders of this build, the preferred first.
const std::vector<const DicomDecoder*>& dicomDecoders();
const DicomDecoder& basicDicomDecoder();  // DicomBasicReader.cpp
#ifndef __EMSCRIPTEN__
const DicomDecoder& dcmtkDicomDecoder();  // DicomToolkit.cpp
#endif

// The first decoder of `decoders` that reads `files` and decodes every one of
// `transferSyntaxUids`; if none decodes them all, the first that reads
// `files` (its error names the file and the syntax it cannot decode).
// nullptr when none reads `files`.
const DicomDecoder* chooseDicomDecoder(const std::vector<const DicomDecoder*>& decoders,
                                       const std::vector<std::string>& transferSyntaxUids,
                                       const FileSet& files);

// The Transfer Syntax UID (0002,0010) of a Part-10 file's meta information;
// "" when the file has no Part-10 header or no such element (then the
// dataset is implicit VR little endian, 1.2.840.10008.1.2, PS3.5 A.1).
std::string dicomTransferSyntaxOf(const ByteSource& file);
// Whether `file` has the Part-10 marker "DICM" at byte 128.
bool hasDicomMarker(const ByteSource& file);

// The series of `named` from the files beside it (FileSet::filesBeside), or
// of the folder (or file) on disk, by the decoder chosen as above.
Volume readDicom(const ByteSource& named, const FileSet& files, const std::string& seriesUid);
Volume readDicomFolder(const std::filesystem::path& folderOrFile, const std::string& seriesUid);

}  // namespace tessera
