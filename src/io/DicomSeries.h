#pragma once
// What a DICOM series reader does once a file's attributes can be read,
// whichever parser read them: DCMTK natively (DicomSeriesReader.cpp) or the
// small reader that also builds for the browser (DicomBasicReader.cpp).
// Series grouping, stack selection, the checks, the LPS geometry (converted
// to the volume's RAS+ once, core/PatientFrame.h) and the rescale live here
// once, so both readers give the same volume with the same affine.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"
#include "tessera/io/DicomSeriesReader.h"

namespace tessera::io_detail {

struct DicomTag {
  std::uint16_t group = 0;
  std::uint16_t element = 0;
  std::string text() const;  // "(0028,0010)"
};

inline constexpr DicomTag kTagRows{0x0028, 0x0010};
inline constexpr DicomTag kTagColumns{0x0028, 0x0011};
inline constexpr DicomTag kTagBitsAllocated{0x0028, 0x0100};
inline constexpr DicomTag kTagBitsStored{0x0028, 0x0101};
inline constexpr DicomTag kTagHighBit{0x0028, 0x0102};
inline constexpr DicomTag kTagPixelRepresentation{0x0028, 0x0103};
inline constexpr DicomTag kTagSamplesPerPixel{0x0028, 0x0002};
inline constexpr DicomTag kTagPhotometric{0x0028, 0x0004};
inline constexpr DicomTag kTagNumberOfFrames{0x0028, 0x0008};
inline constexpr DicomTag kTagPixelSpacing{0x0028, 0x0030};
inline constexpr DicomTag kTagRescaleIntercept{0x0028, 0x1052};
inline constexpr DicomTag kTagRescaleSlope{0x0028, 0x1053};
inline constexpr DicomTag kTagModality{0x0008, 0x0060};
inline constexpr DicomTag kTagSeriesDescription{0x0008, 0x103e};
inline constexpr DicomTag kTagSliceThickness{0x0018, 0x0050};
inline constexpr DicomTag kTagSpacingBetweenSlices{0x0018, 0x0088};
inline constexpr DicomTag kTagSeriesInstanceUid{0x0020, 0x000e};
inline constexpr DicomTag kTagInstanceNumber{0x0020, 0x0013};
inline constexpr DicomTag kTagImagePositionPatient{0x0020, 0x0032};
inline constexpr DicomTag kTagImageOrientationPatient{0x0020, 0x0037};
inline constexpr DicomTag kTagPixelData{0x7fe0, 0x0010};
inline constexpr DicomTag kTagWindowCenter{0x0028, 0x1050};
inline constexpr DicomTag kTagWindowWidth{0x0028, 0x1051};
// Multi-frame objects (PS3.3 C.7.6.16): the functional groups and the
// macros read from them, and the classic ways of placing frames.
inline constexpr DicomTag kTagSharedFunctionalGroups{0x5200, 0x9229};
inline constexpr DicomTag kTagPerFrameFunctionalGroups{0x5200, 0x9230};
inline constexpr DicomTag kTagPlanePositionSequence{0x0020, 0x9113};
inline constexpr DicomTag kTagPlaneOrientationSequence{0x0020, 0x9116};
inline constexpr DicomTag kTagPixelMeasuresSequence{0x0028, 0x9110};
inline constexpr DicomTag kTagPixelValueTransformationSequence{0x0028, 0x9145};
inline constexpr DicomTag kTagFrameVoiLutSequence{0x0028, 0x9132};
inline constexpr DicomTag kTagFrameContentSequence{0x0020, 0x9111};
inline constexpr DicomTag kTagStackId{0x0020, 0x9056};
inline constexpr DicomTag kTagInStackPositionNumber{0x0020, 0x9057};
inline constexpr DicomTag kTagDetectorInformationSequence{0x0054, 0x0022};
inline constexpr DicomTag kTagGridFrameOffsetVector{0x3004, 0x000c};

// Sequences within sequences (a sequence at the top level is level 1) a
// reader accepts. Parsers that recurse per level (DCMTK's; the basic
// reader's walk) would overflow the stack on a crafted file nested
// thousands deep (6,000 levels fit in 216 KB); real objects nest a handful
// (enhanced multi-frame functional groups 3, structured reports tens at
// most).
inline constexpr int kMaxSequenceNesting = 64;

// The refusal of a file nested deeper: "<file>: sequences nested deeper
// than 64 levels; refused".
std::string sequencesTooDeepMessage(const std::string& file);

// A parsed file's top-level attributes, as each parser provides them.
class DicomAttributes {
 public:
  virtual ~DicomAttributes() = default;
  // The value as text without leading/trailing spaces and NULs (an element
  // stored with VR UN gives its bytes, PS3.5 6.2.2); nullopt when absent,
  // unreadable or longer than any attribute read here can be.
  virtual std::optional<std::string> text(DicomTag tag) const = 0;
  // An unsigned short (US, or UN of two bytes); nullopt when absent.
  virtual std::optional<int> uint16(DicomTag tag) const = 0;
  // An unsigned long (UL, or UN of four bytes); nullopt when absent. By
  // default parsed from text(), for attribute sources that give text.
  virtual std::optional<std::uint32_t> uint32(DicomTag tag) const;
  // The items of a sequence (SQ) at this level, in order; empty when absent.
  // The default has none: a source without sequences reads multi-frame
  // objects as classic multi-frame (no functional groups).
  virtual std::vector<std::unique_ptr<DicomAttributes>> items(DicomTag sequence) const;
};

// One image file of a series: what the header says, before any pixel is read.
struct Slice {
  std::filesystem::path file;
  std::string seriesUid;
  std::string seriesDescription;
  std::string modality;
  // For the description: "Little Endian Explicit (1.2.840.10008.1.2.1)".
  std::string transferSyntax;
  int rows = 0;
  int columns = 0;
  int bitsAllocated = 0;
  int bitsStored = 0;
  int highBit = -1;
  bool isSigned = false;
  int samplesPerPixel = 1;
  long frames = 1;
  std::string photometric;
  std::optional<long> instanceNumber;  // of a frame: In-Stack Position Number, else frame + 1
  // A frame of a multi-frame object: its index in the file (0-based; the
  // frame number users see is frame + 1) and its stack: Frame Content's
  // Stack ID, else one per orientation ("1", "2", ... when the file holds
  // several), "" for single-frame files. One volume is one stack.
  int frame = 0;
  std::string stack;
  // Encapsulated pixel data: its fragment count (each frame needs one at least).
  std::optional<std::uint64_t> fragments;
  // The series' window (Window Center/Width, first value, rescaled units).
  std::optional<double> windowCenter;
  std::optional<double> windowWidth;
  std::optional<glm::dvec3> position;      // Image Position (Patient), LPS mm
  std::optional<glm::dvec3> rowDir;        // LPS direction of increasing column index
  std::optional<glm::dvec3> colDir;        // LPS direction of increasing row index
  std::optional<glm::dvec2> pixelSpacing;  // (between rows, between columns)
  double slope = 1.0;
  double intercept = 0.0;
  double sliceThickness = 0.0;
  double spacingBetweenSlices = 0.0;
  // Declared length of uncompressed pixel data, checked before anything is
  // allocated (compressed data is checked once decoded).
  std::optional<std::uint64_t> pixelBytes;
  // For compressed pixel data whose codec bounds its expansion (RLE): the
  // most bytes it can decode to, checked before anything is allocated.
  std::optional<std::uint64_t> decodedBytesBound;
  std::string compression;  // names the codec in that check's message
  // The first malformed attribute, reported only if this slice is read.
  std::string defect;
  double distance = 0.0;  // along the slice normal, set when sorting
};

// A file that could not be used (unparsable, or no codec for its pixels),
// with what its header said as far as it could be parsed.
struct UnreadableFile {
  std::filesystem::path file;
  std::string error;
  std::string seriesUid;               // may be empty
  std::optional<glm::dvec3> position;  // LPS mm, when parsed
};

struct FolderScan {
  std::string where;  // "folder X" or "the N files given"
  std::vector<Slice> slices;
  int nonDicomFiles = 0;
  int nonImageObjects = 0;  // DICOMDIR, reports, ... (no Pixel Data)
  // Skipped, then judged with the series read (see checkUnreadableMembers);
  // a note when they belong to another series.
  std::vector<UnreadableFile> unreadable;
  int subfolders = 0;
};

// The attributes a slice needs; problems are recorded in `defect`, not
// thrown, so that a broken file of a series nobody asked for does no harm.
// The transfer syntax and pixel lengths are the parser's to fill in.
Slice sliceHeader(const std::filesystem::path& file, const DicomAttributes& attributes);

// The slices a parsed header stands for: `header` itself for a single-frame
// file, one per frame for a multi-frame object (io/DicomMultiFrame.cpp),
// placed by its functional groups (enhanced objects) or by the classic
// attributes (Grid Frame Offset Vector, Spacing Between Slices). The parser
// fills in transfer syntax, pixel lengths and fragments before calling this.
std::vector<Slice> framesOf(Slice header, const DicomAttributes& attributes);

// "scan.dcm" for a single-frame file, "scan.dcm frame 7" for a frame of a
// multi-frame one (frames counted from 1, as DICOM numbers them).
std::string sliceName(const Slice& s);

// Two slices (or frames) whose row and column directions agree within 1e-3
// per component, or that both have none: one stack, one volume.
bool sameOrientation(const Slice& a, const Slice& b);

// The numbers of a decimal (DS) or integer (IS) string "a\b\c"; nullopt
// unless there are exactly `count` of them.
std::optional<std::vector<double>> parseNumbers(const std::string& text, std::size_t count);

// Reads the Image Plane and rescale attributes present in `ds` (Image
// Position and Orientation (Patient), Pixel Spacing, Slice Thickness, Spacing
// Between Slices, Rescale Slope and Intercept, Window Center and Width) into
// `s`, leaving those absent as they are; a malformed one is `s`'s defect.
// The top level of a file and the functional-group macros hold the same
// attributes, so one function reads both.
void readPlaneAttributes(const DicomAttributes& ds, Slice& s);

// What an unusable file's header says, as far as it was parsed.
UnreadableFile unreadableFile(const std::filesystem::path& file, std::string error,
                              const DicomAttributes& attributes);

struct StoredRange {
  std::int64_t min = std::numeric_limits<std::int64_t>::max();
  std::int64_t max = std::numeric_limits<std::int64_t>::min();
  std::uint64_t padding = 0;  // bytes after the pixels (see storePixels)
};

// The byte range of frame `s.frame` within pixel data of `length` bytes
// (native, or decoded as a whole): what storePixels gets for it. A file of
// one frame gets all of it (padding is judged there); the last frame of
// several its remainder. InputError naming the file and frame when the data
// ends before the frame does.
std::pair<std::uint64_t, std::uint64_t> frameRange(const Slice& s, std::uint64_t length);

// One slice's decoded pixels, `length` bytes of 8-bit samples or 16-bit
// samples in host byte order, stored into z-plane `z` of `stored` (masked to
// Bits Stored, sign-extended when signed). Pixel data must hold Rows x
// Columns pixels; less than another frame of bytes after them is padding.
StoredRange storePixels(const Slice& s, const void* samples, std::uint64_t length, Volume& stored,
                        int z);

// Decodes `slice` into z-plane `z` of `stored` (through storePixels).
using PixelDecoder = std::function<StoredRange(const Slice& slice, Volume& stored, int z)>;

// InputError unless the scan found images (naming why not: no files,
// non-DICOM files, unreadable ones, subfolders).
void refuseEmpty(const FolderScan& scan, const std::string& what);

// Reads the series `seriesUid` (empty: the one holding `named`, else the
// largest) from what a folder scan found; see DicomSeriesReader.h. Without
// `seriesUid`, a `named` file its series cannot hold is read alone, with a
// note (stderr and the description); errors beside a named file name it.
Volume readSeries(FolderScan scan, const std::string& seriesUid, const std::string& what,
                  const PixelDecoder& decode, const std::filesystem::path& named = {});

// The series of a scan, the largest first.
std::vector<DicomSeriesInfo> listSeries(FolderScan scan);

// How a parser adds one file to a scan; with `mustBeImage`, a file that is
// not a readable image is an InputError instead of a count in the scan.
using FileAdder =
    std::function<void(const std::filesystem::path& file, bool mustBeImage, FolderScan& scan)>;

// Every regular file of `folder` given to `add`; subfolders are counted, not
// entered.
FolderScan scanFolder(const std::filesystem::path& folder, const FileAdder& add);

// The series of a folder, or the series of the one file named (read from the
// files beside it, that file's own errors first; the file alone when its
// series cannot hold it): what the readers' path entry points share.
Volume readFolderOrFile(const std::filesystem::path& folderOrFile, const std::string& seriesUid,
                        const FileAdder& add, const PixelDecoder& decode);

// The series of `folder`, or of the folder holding the file named.
std::vector<DicomSeriesInfo> listFolderSeries(const std::filesystem::path& folder,
                                              const FileAdder& add);

}  // namespace tessera::io_detail
