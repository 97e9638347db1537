// DICOM series -> one volume (Schultz 2016, 6.1 and 7.1.1), through DCMTK:
// DCMTK parses each file and decodes its pixels; the series assembly, the
// checks and the geometry are io/DicomSeries.cpp's, shared with the reader
// that builds without DCMTK (DicomBasicReader.cpp).
#include "tessera/io/DicomSeriesReader.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <utility>

#include "io/DicomNesting.h"
#include "io/DicomSeries.h"
#include "io/DicomToolkit.h"
#include "tessera/core/Error.h"

#include <dcmtk/dcmdata/dcdatset.h>
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcmetinf.h>
#include <dcmtk/dcmdata/dcpixel.h>
#include <dcmtk/dcmdata/dcpixseq.h>
#include <dcmtk/dcmdata/dcsequen.h>
#include <dcmtk/dcmdata/dcstack.h>

namespace tessera {

namespace fs = std::filesystem;
using io_detail::conditionText;
using io_detail::DicomTag;
using io_detail::FolderScan;
using io_detail::Slice;
using io_detail::StoredRange;
using io_detail::transferSyntaxText;
using io_detail::UnreadableFile;

namespace {

// Deflate never compresses by more than 1032:1 (zlib technical details,
// "Maximum compression factor"), which bounds what a deflated dataset holds.
constexpr std::uint64_t kMaxDeflateRatio = 1032;

enum class Probe { Part10, MaybeDataset, NotDicom };

// PS3.10 7.1: a 128-byte preamble, then "DICM". Files without it (ACR-NEMA
// style datasets) usually begin with a tag of group 0x0008 or 0x0002,
// little endian.
Probe probeFile(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  unsigned char buf[132] = {};
  in.read(reinterpret_cast<char*>(buf), sizeof buf);
  const std::streamsize n = in.gcount();
  if (n == 132 && std::memcmp(buf + 128, "DICM", 4) == 0) return Probe::Part10;
  if (n >= 8 && (buf[0] == 0x08 || buf[0] == 0x02) && buf[1] == 0x00) return Probe::MaybeDataset;
  return Probe::NotDicom;
}

// The length an element declares is trusted by DCMTK when its value is first
// read (values over DCM_MaxReadLength stay on disk until then): a corrupt
// length would make it allocate gigabytes. No value can be longer than the
// file holds: its size, or for a deflated dataset what that size inflates
// to at most.
void checkDeclaredLengths(DcmItem& item, const fs::path& file, std::uintmax_t fileSize,
                          bool deflated) {
  const std::uint64_t limit = deflated ? fileSize * kMaxDeflateRatio : fileSize;
  DcmStack stack;
  while (item.nextObject(stack, OFTrue).good()) {
    DcmObject* obj = stack.top();
    if (obj == nullptr || !obj->isLeaf()) continue;
    const Uint32 declared = obj->getLengthField();
    if (declared == DCM_UndefinedLength || declared <= limit) continue;
    DcmTag tag = obj->getTag();
    throw InputError(file.string() + ": element " + tag.toString().c_str() + " " +
                     tag.getTagName() + " declares " + std::to_string(declared) +
                     " bytes but the file has only " + std::to_string(fileSize) +
                     (deflated
                          ? " deflated bytes (at most " + std::to_string(limit) + " once inflated)"
                          : std::string()) +
                     " (corrupt file)");
  }
}

// Loads `file` (large values, i.e. the pixel data, stay on disk until used).
// False when the file is not DICOM; InputError for a Part-10 file that DCMTK
// cannot parse (truncated, corrupt, unknown transfer syntax), whose
// elements declare more bytes than the file holds, or (any DICOM file) whose
// sequences nest too deep for DCMTK's recursive parser.
bool loadDicom(const fs::path& file, DcmFileFormat& ff) {
  const Probe probe = probeFile(file);
  if (probe == Probe::NotDicom) return false;
  std::error_code ec;
  const std::uintmax_t fileSize = fs::file_size(file, ec);
  if (ec) throw InputError(file.string() + ": cannot read: " + ec.message());
  // DCMTK recurses once per nested sequence, without a limit.
  io_detail::checkSequenceNesting(file, probe == Probe::Part10);
  const OFCondition c = ff.loadFile(file.c_str(), EXS_Unknown, EGL_noChange, DCM_MaxReadLength,
                                    probe == Probe::Part10 ? ERM_fileOnly : ERM_dataset);
  if (c.good()) {
    if (ff.getMetaInfo() != nullptr) checkDeclaredLengths(*ff.getMetaInfo(), file, fileSize, false);
    const bool deflated = ff.getDataset()->getOriginalXfer() == EXS_DeflatedLittleEndianExplicit;
    checkDeclaredLengths(*ff.getDataset(), file, fileSize, deflated);
    return true;
  }
  if (probe == Probe::MaybeDataset) return false;
  OFString uid;
  DcmElement* uidElement = nullptr;
  if (ff.getMetaInfo() != nullptr &&
      ff.getMetaInfo()->findAndGetElement(DCM_TransferSyntaxUID, uidElement).good() &&
      uidElement != nullptr && uidElement->getLengthField() <= 64 &&  // UI: 64 chars at most
      uidElement->getOFString(uid, 0).good() && !uid.empty() &&
      DcmXfer(uid.c_str()).getXfer() == EXS_Unknown) {
    throw InputError(file.string() + ": transfer syntax " + uid.c_str() +
                     " is unknown to DCMTK; the file cannot be read");
  }
  throw InputError(file.string() + ": not a readable DICOM file (DCMTK: " + conditionText(c) +
                   "; truncated or corrupt?)");
}

// The value of a short attribute as text, without leading/trailing spaces
// and NULs; nullopt when absent. An element a writer stored with VR UN
// (it did not know the attribute) holds its implicit-VR little-endian value
// (PS3.5 6.2.2), which for the string VRs read here is the text itself. The
// declared length is checked first: this also runs on files that failed to
// load, whose lengths nobody has vetted (see checkDeclaredLengths).
std::optional<std::string> attributeText(DcmItem& ds, const DcmTagKey& tag) {
  constexpr Uint32 kLongestAttribute = 64 * 1024;  // LT holds 10240 characters
  DcmElement* elem = nullptr;
  if (ds.findAndGetElement(tag, elem).bad() || elem == nullptr ||
      elem->getLengthField() > kLongestAttribute) {
    return std::nullopt;
  }
  std::string r;
  if (elem->ident() == EVR_UN) {
    Uint8* bytes = nullptr;
    if (elem->getUint8Array(bytes).bad()) return std::nullopt;
    if (bytes != nullptr) r.assign(reinterpret_cast<const char*>(bytes), elem->getLength());
  } else {
    OFString s;
    if (elem->getOFStringArray(s).bad()) return std::nullopt;
    r.assign(s.c_str(), s.length());
  }
  const auto b = r.find_first_not_of(std::string(" \0", 2));
  const auto e = r.find_last_not_of(std::string(" \0", 2));
  return b == std::string::npos ? std::string() : r.substr(b, e - b + 1);
}

std::string stringAttr(DcmItem& ds, const DcmTagKey& tag) {
  return attributeText(ds, tag).value_or("");
}

// An unsigned short (US), also when stored as UN (two little-endian bytes).
std::optional<int> uint16Attr(DcmItem& ds, const DcmTagKey& tag) {
  Uint16 v = 0;
  if (ds.findAndGetUint16(tag, v).good()) return v;
  DcmElement* elem = nullptr;
  Uint8* bytes = nullptr;
  if (ds.findAndGetElement(tag, elem).good() && elem != nullptr && elem->ident() == EVR_UN &&
      elem->getLength() == 2 && elem->getUint8Array(bytes).good() && bytes != nullptr) {
    return bytes[0] | (bytes[1] << 8);
  }
  return std::nullopt;
}

// DCMTK's dataset as the shared series code reads it.
class DcmAttributes final : public io_detail::DicomAttributes {
 public:
  explicit DcmAttributes(DcmItem& ds) : ds_(ds) {}
  std::optional<std::string> text(DicomTag tag) const override {
    return attributeText(ds_, DcmTagKey(tag.group, tag.element));
  }
  std::optional<int> uint16(DicomTag tag) const override {
    return uint16Attr(ds_, DcmTagKey(tag.group, tag.element));
  }
  std::optional<std::uint32_t> uint32(DicomTag tag) const override {
    Uint32 v = 0;
    if (ds_.findAndGetUint32(DcmTagKey(tag.group, tag.element), v).good()) return v;
    return io_detail::DicomAttributes::uint32(tag);  // UN or text
  }
  std::vector<std::unique_ptr<io_detail::DicomAttributes>> items(DicomTag tag) const override {
    std::vector<std::unique_ptr<io_detail::DicomAttributes>> out;
    DcmSequenceOfItems* seq = nullptr;
    if (ds_.findAndGetSequence(DcmTagKey(tag.group, tag.element), seq).bad() || seq == nullptr) {
      return out;
    }
    for (unsigned long i = 0; i < seq->card(); ++i) {
      if (DcmItem* item = seq->getItem(i)) out.push_back(std::make_unique<DcmAttributes>(*item));
    }
    return out;
  }

 private:
  DcmItem& ds_;
};

// The number of fragments of encapsulated pixel data (the offset table
// item is none); nullopt when DCMTK cannot say.
std::optional<std::uint64_t> fragmentCount(DcmDataset& ds, E_TransferSyntax xfer) {
  DcmElement* elem = nullptr;
  if (ds.findAndGetElement(DCM_PixelData, elem).bad() || elem == nullptr ||
      elem->ident() != EVR_PixelData) {
    return std::nullopt;
  }
  DcmPixelSequence* seq = nullptr;
  if (static_cast<DcmPixelData*>(elem)->getEncapsulatedRepresentation(xfer, nullptr, seq).bad() ||
      seq == nullptr || seq->card() == 0) {
    return std::nullopt;
  }
  return seq->card() - 1;
}

// The shared header, and what only DCMTK knows: the transfer syntax and
// the length of uncompressed pixel data (or the fragments of compressed);
// one slice per frame of a multi-frame object.
std::vector<Slice> sliceHeaders(const fs::path& file, DcmFileFormat& ff) {
  DcmDataset& ds = *ff.getDataset();
  const DcmAttributes attributes(ds);
  Slice s = io_detail::sliceHeader(file, attributes);
  const E_TransferSyntax xfer = ds.getOriginalXfer();
  s.transferSyntax = transferSyntaxText(xfer);
  DcmElement* pixels = nullptr;
  if (!DcmXfer(xfer).isEncapsulated() && ds.findAndGetElement(DCM_PixelData, pixels).good() &&
      pixels != nullptr) {
    s.pixelBytes = pixels->getLength();
  }
  if (DcmXfer(xfer).isEncapsulated()) s.fragments = fragmentCount(ds, xfer);
  return io_detail::framesOf(std::move(s), attributes);
}

UnreadableFile unreadableFile(const fs::path& file, std::string error, DcmDataset& ds) {
  return io_detail::unreadableFile(file, std::move(error), DcmAttributes(ds));
}

void addFile(const fs::path& file, bool mustBeImage, FolderScan& scan) {
  DcmFileFormat ff;
  bool isDicom = false;
  try {
    isDicom = loadDicom(file, ff);
  } catch (const InputError& e) {
    if (mustBeImage) throw;
    // What was parsed before the failure usually includes the series UID.
    scan.unreadable.push_back(unreadableFile(file, e.what(), *ff.getDataset()));
    return;
  }
  if (!isDicom) {
    if (mustBeImage) {
      throw InputError(file.string() +
                       ": not a DICOM file (no 'DICM' marker at byte 128, and not a DICOM "
                       "dataset either)");
    }
    ++scan.nonDicomFiles;
    return;
  }
  DcmDataset& ds = *ff.getDataset();
  if (!ds.tagExists(DCM_PixelData)) {
    if (mustBeImage) {
      throw InputError(file.string() + ": a DICOM object without Pixel Data (7FE0,0010) (" +
                       stringAttr(ds, DCM_Modality) + "); not an image");
    }
    ++scan.nonImageObjects;
    return;
  }
  // Known now rather than when the pixels are decoded, so that such a file
  // beside readable copies of its slice (JPEG 2000 next to JPEG) is skipped.
  if (!io_detail::canDecodePixels(ds.getOriginalXfer())) {
    std::string error = io_detail::undecodableSyntaxMessage(file.string(), ds.getOriginalXfer());
    if (mustBeImage) throw InputError(error);
    scan.unreadable.push_back(unreadableFile(file, std::move(error), ds));
    return;
  }
  for (auto& frame : sliceHeaders(file, ff)) scan.slices.push_back(std::move(frame));
}

// One file's pixel data, loaded (and decoded) once for all its frames.
struct LoadedPixels {
  fs::path file;
  std::unique_ptr<DcmFileFormat> ff;
  const void* samples = nullptr;  // 8-bit or host-order 16-bit
  std::uint64_t length = 0;
};

// Loads `s`'s file and decodes its whole pixel data (every frame).
void loadPixels(const Slice& s, LoadedPixels& out) {
  const std::string f = s.file.string();
  out.file.clear();
  out.samples = nullptr;
  out.ff = std::make_unique<DcmFileFormat>();
  if (!loadDicom(s.file, *out.ff)) throw InputError(f + ": is no longer a DICOM file");
  DcmDataset& ds = *out.ff->getDataset();
  const E_TransferSyntax xfer = ds.getOriginalXfer();
  if (DcmXfer(xfer).isEncapsulated()) {
    io_detail::checkJpegFragments(ds, f);
    const OFCondition c = ds.chooseRepresentation(EXS_LittleEndianExplicit, nullptr);
    if (!io_detail::canDecodePixels(xfer)) {
      throw InputError(io_detail::undecodableSyntaxMessage(f, xfer));
    }
    if (c.bad() || !ds.canWriteXfer(EXS_LittleEndianExplicit)) {
      throw InputError(f + ": the " + transferSyntaxText(xfer) +
                       " pixel data cannot be decoded (DCMTK: " + conditionText(c) +
                       "; corrupt or truncated?)");
    }
  }
  DcmElement* elem = nullptr;
  if (ds.findAndGetElement(DCM_PixelData, elem).bad() || elem == nullptr) {
    throw InputError(f + ": no Pixel Data (7FE0,0010)");
  }
  const auto loadFailed = [&](const OFCondition& c) {
    return InputError(f + ": pixel data cannot be read (DCMTK: " + conditionText(c) +
                      "; truncated file?)");
  };
  OFCondition c;
  if (s.bitsAllocated == 8) {
    Uint8* p = nullptr;
    c = elem->getUint8Array(p);
    out.samples = p;
  } else {
    Uint16* p = nullptr;
    c = elem->getUint16Array(p);
    out.samples = p;
  }
  if (c.bad() || out.samples == nullptr) throw loadFailed(c);
  out.length = elem->getLength();
  out.file = s.file;
}

// Decodes slices into z-planes of `stored`; the frames of one file share
// one load and decode (the file last read is kept).
io_detail::PixelDecoder pixelDecoder() {
  auto loaded = std::make_shared<LoadedPixels>();
  return [loaded](const Slice& s, Volume& stored, int z) -> StoredRange {
    if (loaded->file != s.file || loaded->samples == nullptr) loadPixels(s, *loaded);
    const auto [begin, length] = io_detail::frameRange(s, loaded->length);
    const auto* bytes = static_cast<const std::uint8_t*>(loaded->samples) + begin;
    return io_detail::storePixels(s, bytes, length, stored, z);
  };
}

}  // namespace

Volume readDicomSeries(const fs::path& folderOrFile, const std::string& seriesUid) {
  io_detail::initDicomToolkit();
  return io_detail::readFolderOrFile(folderOrFile, seriesUid, addFile, pixelDecoder());
}

Volume readDicomFiles(const std::vector<fs::path>& files, const std::string& seriesUid) {
  io_detail::initDicomToolkit();
  if (files.empty()) throw InputError("readDicomFiles: no files given");
  FolderScan scan;
  scan.where = "the " + std::to_string(files.size()) + " files given";
  for (const auto& f : files) {
    std::error_code ec;
    if (!fs::is_regular_file(f, ec)) throw InputError(f.string() + ": no such file");
    addFile(f, true, scan);
  }
  return io_detail::readSeries(std::move(scan), seriesUid, files.front().string(), pixelDecoder());
}

std::vector<DicomSeriesInfo> listDicomSeries(const fs::path& folder) {
  io_detail::initDicomToolkit();
  return io_detail::listFolderSeries(folder, addFile);
}

}  // namespace tessera
