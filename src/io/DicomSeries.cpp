// The series assembly shared by the DICOM readers (see DicomSeries.h).
// Attribute meanings follow DICOM PS3.3 C.7.6.2 (Image Plane module: position,
// orientation, pixel spacing) and C.7.6.3 (Image Pixel module: rows, columns,
// bits, pixel representation); rescale follows C.11.1.1.2. DICOM's patient
// frame is LPS+; the volume's affine is RAS+ (core/PatientFrame.h), so every
// position and direction is converted once, in applyGeometry.
#include "io/DicomSeries.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <system_error>
#include <utility>

#include <glm/geometric.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"

namespace tessera::io_detail {

namespace fs = std::filesystem;

std::string DicomTag::text() const {
  char buf[16];
  std::snprintf(buf, sizeof buf, "(%04x,%04x)", group, element);
  return buf;
}

std::string sequencesTooDeepMessage(const std::string& file) {
  return file + ": sequences nested deeper than " + std::to_string(kMaxSequenceNesting) +
         " levels; refused";
}

namespace {

// Direction cosines of two slices agree when every component is within this.
constexpr double kOrientationTolerance = 1e-3;
// Consecutive slice gaps may differ from the median gap by this fraction.
constexpr double kGapTolerance = 0.01;
// Largest distance of a slice position from the straight line through the
// first and last slice, in pixels, still read as one regular stack.
constexpr double kIrregularTolerancePixels = 0.5;
// Positions closer than this (mm) are the same slice position.
constexpr double kSamePositionMm = 0.01;

std::string quoted(const std::string& s) {
  return "'" + s + "'";
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string vecText(glm::dvec3 v) {
  return "(" + number(v.x) + ", " + number(v.y) + ", " + number(v.z) + ")";
}

// "Rows (0028,0010)": the name users know and the tag, each once.
std::string attributeName(const char* name, DicomTag tag) {
  return std::string(name) + " " + tag.text();
}

// How a malformed value is shown in a message: its text, or its size when
// it is not text at all.
std::string shownValue(const std::string& text) {
  const bool printable = std::all_of(text.begin(), text.end(), [](char c) {
    return static_cast<unsigned char>(c) >= 0x20 && static_cast<unsigned char>(c) < 0x7f;
  });
  return printable ? quoted(text) : std::to_string(text.size()) + " bytes that are not text";
}

}  // namespace

bool sameOrientation(const Slice& a, const Slice& b) {
  if (a.rowDir.has_value() != b.rowDir.has_value()) return false;
  if (!a.rowDir) return true;
  const glm::dvec3 dr = *a.rowDir - *b.rowDir;
  const glm::dvec3 dc = *a.colDir - *b.colDir;
  return std::max({std::abs(dr.x), std::abs(dr.y), std::abs(dr.z), std::abs(dc.x), std::abs(dc.y),
                   std::abs(dc.z)}) <= kOrientationTolerance;
}

// Parsed without the C locale's
// help (std::from_chars), so a decimal comma never passes.
std::optional<std::vector<double>> parseNumbers(const std::string& text, std::size_t count) {
  std::vector<double> out;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    std::size_t end = text.find('\\', begin);
    if (end == std::string::npos) end = text.size();
    std::size_t a = text.find_first_not_of(' ', begin);
    std::size_t b = end;
    while (b > a && text[b - 1] == ' ') --b;
    if (a == std::string::npos || a >= b) return std::nullopt;
    if (text[a] == '+') ++a;
    double v = 0;
    const auto r = std::from_chars(text.data() + a, text.data() + b, v);
    if (r.ec != std::errc() || r.ptr != text.data() + b || !std::isfinite(v)) return std::nullopt;
    out.push_back(v);
    begin = end + 1;
  }
  if (out.size() != count) return std::nullopt;
  return out;
}

std::optional<std::uint32_t> DicomAttributes::uint32(DicomTag tag) const {
  const auto t = text(tag);
  const auto v = t ? parseNumbers(*t, 1) : std::nullopt;
  if (!v || (*v)[0] < 0 || (*v)[0] > 4294967295.0 || std::floor((*v)[0]) != (*v)[0]) {
    return std::nullopt;
  }
  return static_cast<std::uint32_t>((*v)[0]);
}

std::vector<std::unique_ptr<DicomAttributes>> DicomAttributes::items(DicomTag) const {
  return {};
}

std::string sliceName(const Slice& s) {
  return s.frames > 1 ? s.file.string() + " frame " + std::to_string(s.frame + 1) : s.file.string();
}

void readPlaneAttributes(const DicomAttributes& ds, Slice& s) {
  auto defect = [&](const std::string& msg) {
    if (s.defect.empty()) s.defect = msg;
  };
  // Decimal strings: absent is fine (nullopt), present but malformed is a defect.
  auto numbers = [&](DicomTag tag, const char* name,
                     std::size_t count) -> std::optional<std::vector<double>> {
    const auto text = ds.text(tag);
    if (!text || text->empty()) return std::nullopt;
    auto v = parseNumbers(*text, count);
    if (!v) {
      defect(attributeName(name, tag) + " is " + shownValue(*text) + ", expected " +
             std::to_string(count) + (count == 1 ? " number" : " numbers"));
    }
    return v;
  };
  if (auto p = numbers(kTagImagePositionPatient, "Image Position (Patient)", 3)) {
    s.position = glm::dvec3((*p)[0], (*p)[1], (*p)[2]);
  }
  if (auto o = numbers(kTagImageOrientationPatient, "Image Orientation (Patient)", 6)) {
    const glm::dvec3 r((*o)[0], (*o)[1], (*o)[2]);
    const glm::dvec3 c((*o)[3], (*o)[4], (*o)[5]);
    if (glm::length(r) < 0.5 || glm::length(c) < 0.5 ||
        std::abs(glm::dot(glm::normalize(r), glm::normalize(c))) > kOrientationTolerance) {
      defect("Image Orientation (Patient) " + vecText(r) + " " + vecText(c) +
             " is not two perpendicular unit vectors");
    } else {
      s.rowDir = glm::normalize(r);
      // Exactly perpendicular to the row, as the normal and the affine need.
      s.colDir = glm::normalize(c - glm::dot(c, *s.rowDir) * *s.rowDir);
    }
  }
  if (auto p = numbers(kTagPixelSpacing, "Pixel Spacing", 2)) {
    if ((*p)[0] <= 0 || (*p)[1] <= 0) {
      defect("Pixel Spacing is " + number((*p)[0]) + "\\" + number((*p)[1]) +
             ", expected two positive numbers");
    } else {
      s.pixelSpacing = glm::dvec2((*p)[0], (*p)[1]);
    }
  }
  if (auto v = numbers(kTagRescaleSlope, "Rescale Slope", 1)) {
    if ((*v)[0] == 0.0) defect("Rescale Slope is 0");
    s.slope = (*v)[0];
  }
  if (auto v = numbers(kTagRescaleIntercept, "Rescale Intercept", 1)) s.intercept = (*v)[0];
  if (auto v = numbers(kTagSliceThickness, "Slice Thickness", 1)) s.sliceThickness = (*v)[0];
  if (auto v = numbers(kTagSpacingBetweenSlices, "Spacing Between Slices", 1)) {
    s.spacingBetweenSlices = (*v)[0];
  }
  // Window Center/Width may hold several windows; the first is the default
  // (PS3.3 C.11.2.1.2), in rescaled units.
  const auto firstOf = [&](DicomTag tag) -> std::optional<double> {
    const auto t = ds.text(tag);
    if (!t) return std::nullopt;
    const auto v = parseNumbers(t->substr(0, t->find('\\')), 1);
    return v ? std::optional<double>((*v)[0]) : std::nullopt;
  };
  const auto center = firstOf(kTagWindowCenter);
  const auto width = firstOf(kTagWindowWidth);
  if (center && width && *width > 0) {
    s.windowCenter = center;
    s.windowWidth = width;
  }
}

// Reads the attributes a slice needs; problems are recorded in `defect`, not
// thrown, so that a broken file of a series nobody asked for does no harm.
Slice sliceHeader(const fs::path& file, const DicomAttributes& ds) {
  Slice s;
  s.file = file;
  s.seriesUid = ds.text(kTagSeriesInstanceUid).value_or("");
  s.seriesDescription = ds.text(kTagSeriesDescription).value_or("");
  s.modality = ds.text(kTagModality).value_or("");
  s.photometric = ds.text(kTagPhotometric).value_or("");

  auto defect = [&](const std::string& msg) {
    if (s.defect.empty()) s.defect = msg;
  };
  // The Image Pixel module's type 1 attributes (PS3.3 C.7.6.3), all named at once.
  std::vector<std::string> missing;
  auto required = [&](DicomTag tag, const char* name, int& out) {
    if (const auto v = ds.uint16(tag)) {
      out = *v;
    } else {
      missing.push_back(attributeName(name, tag));
    }
  };
  required(kTagRows, "Rows", s.rows);
  required(kTagColumns, "Columns", s.columns);
  required(kTagBitsAllocated, "Bits Allocated", s.bitsAllocated);
  if (!missing.empty()) {
    std::string list;
    for (std::size_t i = 0; i < missing.size(); ++i) {
      list += (i == 0 ? "" : i + 1 == missing.size() ? " or " : ", ") + missing[i];
    }
    defect("has Pixel Data but no " + list + "; not an image this reader can use");
  }
  s.bitsStored = ds.uint16(kTagBitsStored).value_or(s.bitsAllocated);
  s.highBit = ds.uint16(kTagHighBit).value_or(s.bitsStored - 1);
  s.samplesPerPixel = ds.uint16(kTagSamplesPerPixel).value_or(1);
  s.isSigned = ds.uint16(kTagPixelRepresentation).value_or(0) == 1;

  // Optional integers: a malformed one is treated as absent.
  auto integer = [&](DicomTag tag) -> std::optional<long> {
    const auto t = ds.text(tag);
    const auto v = t ? parseNumbers(*t, 1) : std::nullopt;
    if (!v || std::floor((*v)[0]) != (*v)[0] || std::abs((*v)[0]) > 2147483647.0) {
      return std::nullopt;
    }
    return static_cast<long>((*v)[0]);
  };
  s.frames = integer(kTagNumberOfFrames).value_or(1);
  s.instanceNumber = integer(kTagInstanceNumber);

  readPlaneAttributes(ds, s);
  return s;
}

// What an unusable file's header says, as far as it was parsed.
UnreadableFile unreadableFile(const fs::path& file, std::string error, const DicomAttributes& ds) {
  UnreadableFile u{file, std::move(error), ds.text(kTagSeriesInstanceUid).value_or(""),
                   std::nullopt};
  if (const auto t = ds.text(kTagImagePositionPatient)) {
    if (const auto p = parseNumbers(*t, 3)) u.position = glm::dvec3((*p)[0], (*p)[1], (*p)[2]);
  }
  return u;
}

namespace {

// One stack of one series: the slices of one volume. Single-frame files
// have no stack ("") and form one group per series; the frames of
// multi-frame objects form one group per stack.
struct SeriesGroup {
  std::string uid;
  std::string stack;
  std::vector<Slice> slices;
  bool severalStacks = false;  // other groups share the UID: the key names the stack
  // What --series takes to choose this group: the UID, with ":stack" when
  // the series holds several stacks.
  std::string key() const { return severalStacks ? uid + ":" + stack : uid; }
  std::string label() const {
    const Slice& s = slices.front();
    std::string t = uid.empty() && !severalStacks ? "(no Series Instance UID)" : key();
    t += " (" + std::to_string(slices.size()) + " slice" + (slices.size() == 1 ? "" : "s");
    if (s.frames > 1) t += " of " + s.file.filename().string();
    if (!s.modality.empty()) t += ", " + s.modality;
    if (!s.seriesDescription.empty()) t += ", \"" + s.seriesDescription + "\"";
    return t + ")";
  }
};

// Series by Series Instance UID and stack, the largest first.
std::vector<SeriesGroup> groupSeries(std::vector<Slice> slices) {
  std::map<std::pair<std::string, std::string>, std::vector<Slice>> byKey;
  for (auto& s : slices) byKey[{s.seriesUid, s.stack}].push_back(std::move(s));
  std::map<std::string, int> stacksOf;
  for (const auto& [key, v] : byKey) ++stacksOf[key.first];
  std::vector<SeriesGroup> groups;
  for (auto& [key, v] : byKey) {
    groups.push_back({key.first, key.second, std::move(v), stacksOf[key.first] > 1});
  }
  std::stable_sort(groups.begin(), groups.end(), [](const SeriesGroup& a, const SeriesGroup& b) {
    return a.slices.size() > b.slices.size();
  });
  return groups;
}

std::string othersText(const std::vector<SeriesGroup>& groups, std::size_t chosen) {
  std::string t;
  int listed = 0;
  for (std::size_t i = 0; i < groups.size(); ++i) {
    if (i == chosen) continue;
    if (listed == 5) {
      t += ", ... and " + std::to_string(groups.size() - 1 - 5) + " more";
      break;
    }
    t += (listed == 0 ? "" : ", ") + groups[i].label();
    ++listed;
  }
  return t;
}

// The group to read: the one `uid` names when given (a Series Instance UID,
// its largest stack, or "UID:stack"), else the one holding the `named` file
// (a file names its own series, also when it has no UID), else the largest.
std::size_t chooseGroup(const std::vector<SeriesGroup>& groups, const std::string& uid,
                        const fs::path& named, const std::string& what) {
  const auto holds = [&](const SeriesGroup& g) {
    if (!uid.empty()) return g.uid == uid || (g.severalStacks && g.key() == uid);
    return std::any_of(g.slices.begin(), g.slices.end(),
                       [&](const Slice& s) { return s.file == named; });
  };
  if (uid.empty() && named.empty()) return 0;
  const auto it = std::find_if(groups.begin(), groups.end(), holds);
  if (it != groups.end()) return static_cast<std::size_t>(it - groups.begin());
  if (!uid.empty()) {
    throw InputError(what + ": no series " + uid + " (Series Instance UID, or UID:stack)" +
                     "; found: " + othersText(groups, groups.size()));
  }
  throw InputError(what + ": the file was not found again when its folder was read");
}

bool samePixelSpacing(const Slice& a, const Slice& b) {
  if (a.pixelSpacing.has_value() != b.pixelSpacing.has_value()) return false;
  return !a.pixelSpacing ||
         glm::length(*a.pixelSpacing - *b.pixelSpacing) <= 1e-3 * glm::length(*b.pixelSpacing);
}

// One Series Instance UID can hold several stacks (a localizer beside its
// slices, reconstructions of other sizes or orientations): slices of one
// stack share size, frame count, pixel type, orientation and pixel spacing.
bool sameStack(const Slice& s, const Slice& r) {
  return s.rows == r.rows && s.columns == r.columns && s.frames == r.frames &&
         s.bitsAllocated == r.bitsAllocated && s.isSigned == r.isSigned && sameOrientation(s, r) &&
         samePixelSpacing(s, r);
}

// A named file selects its own stack. Returns how many others were left out.
std::size_t keepStackOf(std::vector<Slice>& slices, const fs::path& named) {
  const auto ref =
      std::find_if(slices.begin(), slices.end(), [&](const Slice& s) { return s.file == named; });
  if (ref == slices.end()) return 0;
  const Slice r = *ref;
  const std::size_t before = slices.size();
  std::erase_if(slices, [&](const Slice& s) { return !sameStack(s, r); });
  return before - slices.size();
}

// Files of the series read that could not be used are judged against the
// slices that could: one at a readable slice's position is another encoding
// or a broken copy of that slice (pydicom's MR_truncated.dcm beside
// MR_small.dcm) and is skipped; one elsewhere, or of unknown position in a
// positioned series, is a slice the volume would lack, and its error is the
// reason the series cannot be read.
void checkUnreadableMembers(const std::vector<UnreadableFile>& members,
                            const std::vector<Slice>& slices) {
  const bool positioned =
      std::any_of(slices.begin(), slices.end(), [](const Slice& s) { return s.position; });
  for (const auto& u : members) {
    const bool duplicate =
        u.position ? std::any_of(slices.begin(), slices.end(),
                                 [&](const Slice& s) {
                                   return s.position &&
                                          glm::length(*s.position - *u.position) <= kSamePositionMm;
                                 })
                   : !positioned;
    if (!duplicate) {
      throw InputError(
          u.error + " (a slice of the series read" +
          (u.position ? " at Image Position (Patient) " + vecText(*u.position) : std::string()) +
          ": without it the volume would be incomplete)");
    }
  }
}

// Pixel data must hold Rows x Columns pixels. Bytes beyond that, less than
// another frame, are padding and ignored: one byte keeps odd lengths even
// (PS3.5 8.1.1), some writers pad more (pydicom's MR_small_padded.dcm). A
// whole frame more is data this reader would misread. Returns the padding.
std::uint64_t checkPixelBytes(const Slice& s, std::uint64_t length) {
  const std::uint64_t bytes = static_cast<std::uint64_t>(s.bitsAllocated / 8);
  const std::uint64_t expected =
      static_cast<std::uint64_t>(s.rows) * static_cast<std::uint64_t>(s.columns) * bytes;
  if (length < expected || (length > expected + 1 && length >= 2 * expected)) {
    throw InputError(sliceName(s) + ": pixel data has " + std::to_string(length) + " bytes, but " +
                     std::to_string(s.columns) + "x" + std::to_string(s.rows) + " pixels x " +
                     std::to_string(bytes) + " bytes = " + std::to_string(expected) + " bytes" +
                     (length < expected ? " (truncated)"
                      : s.frames > 1    ? " (a frame holds no more)"
                                        : " (more than one frame, but Number of Frames is 1)"));
  }
  return length - expected;
}

// Checks one slice on its own: what any single file must satisfy to be read.
void checkSlice(const Slice& s) {
  const std::string f = s.file.string();
  if (!s.defect.empty()) throw InputError(f + ": " + s.defect);
  if (s.samplesPerPixel != 1) {
    throw InputError(f + ": Samples per Pixel is " + std::to_string(s.samplesPerPixel) + " (" +
                     (s.photometric.empty() ? "colour" : s.photometric) +
                     "); only single-sample greyscale images are supported");
  }
  if (!s.photometric.empty() && s.photometric != "MONOCHROME1" && s.photometric != "MONOCHROME2") {
    throw InputError(f + ": Photometric Interpretation is " + s.photometric +
                     "; only MONOCHROME1/MONOCHROME2 are supported");
  }
  if (s.rows <= 0 || s.columns <= 0) {
    throw InputError(f + ": image is " + std::to_string(s.columns) + "x" + std::to_string(s.rows) +
                     " pixels (Columns x Rows); expected at least 1x1");
  }
  if (s.bitsAllocated != 8 && s.bitsAllocated != 16) {
    throw InputError(f + ": Bits Allocated is " + std::to_string(s.bitsAllocated) +
                     "; only 8 and 16 are supported");
  }
  if (s.bitsStored < 1 || s.bitsStored > s.bitsAllocated || s.highBit != s.bitsStored - 1) {
    throw InputError(f + ": Bits Stored " + std::to_string(s.bitsStored) + " / High Bit " +
                     std::to_string(s.highBit) + " with Bits Allocated " +
                     std::to_string(s.bitsAllocated) +
                     " is not supported (expected High Bit = Bits Stored - 1)");
  }
  if (s.pixelBytes && s.frames == 1) checkPixelBytes(s, *s.pixelBytes);
  const std::uint64_t expected =
      static_cast<std::uint64_t>(s.rows) * static_cast<std::uint64_t>(s.columns) *
      static_cast<std::uint64_t>(s.bitsAllocated / 8) * static_cast<std::uint64_t>(s.frames);
  if (s.decodedBytesBound && expected > *s.decodedBytesBound) {
    throw InputError(f + ": " + std::to_string(s.columns) + "x" + std::to_string(s.rows) +
                     " pixels" +
                     (s.frames > 1 ? " x " + std::to_string(s.frames) + " frames" : std::string()) +
                     " need " + std::to_string(expected) + " bytes, but its " + s.compression +
                     " pixel data can decode to at most " + std::to_string(*s.decodedBytesBound) +
                     " (truncated or corrupt)");
  }
}

// Checks that every slice agrees with the others on what makes them one
// volume; throws naming the file that differs.
void checkConsistent(const std::vector<Slice>& slices) {
  // The most common size is the reference, so the odd file is the one named.
  std::map<std::pair<int, int>, std::size_t> sizes;
  for (const auto& s : slices) ++sizes[{s.rows, s.columns}];
  const auto common = std::max_element(sizes.begin(), sizes.end(), [](auto& a, auto& b) {
                        return a.second < b.second;
                      })->first;
  const Slice* ref = nullptr;
  for (const auto& s : slices) {
    if (std::make_pair(s.rows, s.columns) == common) {
      ref = &s;
      break;
    }
  }
  for (const auto& s : slices) {
    if (s.rows != ref->rows || s.columns != ref->columns) {
      throw InputError(sliceName(s) + ": Rows x Columns is " + std::to_string(s.rows) + "x" +
                       std::to_string(s.columns) + ", but the other slices of the series (e.g. " +
                       sliceName(*ref) + ") are " + std::to_string(ref->rows) + "x" +
                       std::to_string(ref->columns));
    }
    if (s.bitsAllocated != ref->bitsAllocated || s.isSigned != ref->isSigned) {
      throw InputError(sliceName(s) + ": " + std::to_string(s.bitsAllocated) + "-bit " +
                       (s.isSigned ? "signed" : "unsigned") + " pixels, but " + sliceName(*ref) +
                       " has " + std::to_string(ref->bitsAllocated) + "-bit " +
                       (ref->isSigned ? "signed" : "unsigned"));
    }
    if (s.pixelSpacing.has_value() != ref->pixelSpacing.has_value() ||
        (s.pixelSpacing && glm::length(*s.pixelSpacing - *ref->pixelSpacing) >
                               1e-3 * glm::length(*ref->pixelSpacing))) {
      auto text = [](const Slice& x) {
        return x.pixelSpacing ? number(x.pixelSpacing->x) + "\\" + number(x.pixelSpacing->y)
                              : std::string("absent");
      };
      throw InputError(sliceName(s) + ": Pixel Spacing is " + text(s) + ", but " + sliceName(*ref) +
                       " has " + text(*ref));
    }
  }
}

// Where the voxels lie, in DICOM's LPS patient frame; converted to RAS when
// the volume is made (core/PatientFrame.h).
struct Geometry {
  glm::dmat3 direction{1.0};  // LPS; columns: row, column, slice step (unit)
  glm::dvec3 spacing{1.0};
  glm::dvec3 origin{0.0};  // LPS position of voxel (0,0,0)'s centre
  std::string source = "DICOM IPP/IOP (LPS -> RAS)";
  std::vector<std::string> notes;  // assumptions made, for the description
};

// Row and column directions shared by every slice. Without any Image
// Orientation (Patient), axial slices (1\0\0\0\1\0, identity direction)
// are assumed.
void sliceAxes(const std::vector<Slice>& slices, Geometry& g) {
  const Slice& first = slices.front();
  for (const auto& s : slices) {
    if (s.rowDir.has_value() != first.rowDir.has_value()) {
      const Slice& without = s.rowDir ? first : s;
      const Slice& with = s.rowDir ? s : first;
      throw InputError(sliceName(without) + ": no Image Orientation (Patient) (0020,0037), but " +
                       sliceName(with) +
                       " of the same series has one; slices of one volume must share it");
    }
    if (!sameOrientation(s, first)) {
      throw InputError(sliceName(s) + ": Image Orientation (Patient) is " + vecText(*s.rowDir) +
                       " " + vecText(*s.colDir) + ", but " + sliceName(first) + " has " +
                       vecText(*first.rowDir) + " " + vecText(*first.colDir) +
                       "; slices of one volume must share an orientation");
    }
  }
  if (first.rowDir) {
    g.direction[0] = *first.rowDir;
    g.direction[1] = *first.colDir;
  } else {
    g.source += "; no Image Orientation (Patient): axial assumed";
    g.notes.push_back("no Image Orientation (Patient): axial 1\\0\\0\\0\\1\\0 assumed");
  }
  g.direction[2] = glm::cross(g.direction[0], g.direction[1]);
}

// One slice: its plane from IPP/IOP, the third axis along the normal with
// Spacing Between Slices, else Slice Thickness, else 1 mm.
void singleSliceGeometry(const Slice& s, Geometry& g) {
  if (s.position) {
    g.origin = *s.position;
  } else {
    g.source += "; no Image Position (Patient): origin 0";
    g.notes.push_back("no Image Position (Patient): origin assumed at 0");
  }
  if (s.spacingBetweenSlices > 0) {
    g.spacing.z = s.spacingBetweenSlices;
    g.source += "; one slice: z spacing from Spacing Between Slices";
  } else if (s.sliceThickness > 0) {
    g.spacing.z = s.sliceThickness;
    g.source += "; one slice: z spacing from Slice Thickness";
  } else {
    g.source += "; one slice: z spacing 1 assumed";
    g.notes.push_back("one slice without Slice Thickness: z spacing assumed 1");
  }
}

// Sorts `slices` by position along `normal` and checks the gaps: duplicate
// positions, missing slices and uneven spacing are errors naming two files.
// Returns the median gap.
double sortAndCheckGaps(std::vector<Slice>& slices, const glm::dvec3& normal) {
  for (const auto& s : slices) {
    if (!s.position) {
      throw InputError(sliceName(s) +
                       ": no Image Position (Patient) (0020,0032); the slices of a series cannot "
                       "be ordered without it");
    }
  }
  for (auto& s : slices) s.distance = glm::dot(*s.position, normal);
  std::stable_sort(slices.begin(), slices.end(),
                   [](const Slice& a, const Slice& b) { return a.distance < b.distance; });
  std::vector<double> gaps;
  for (std::size_t i = 0; i + 1 < slices.size(); ++i) {
    gaps.push_back(slices[i + 1].distance - slices[i].distance);
  }
  std::vector<double> sorted = gaps;
  std::sort(sorted.begin(), sorted.end());
  const std::size_t mid = sorted.size() / 2;
  const double median =
      sorted.size() % 2 == 1 ? sorted[mid] : 0.5 * (sorted[mid - 1] + sorted[mid]);
  const double tolerance = kGapTolerance * median;
  for (std::size_t i = 0; i < gaps.size(); ++i) {
    const Slice& a = slices[i];
    const Slice& b = slices[i + 1];
    const std::string pair = sliceName(a) + " and " + sliceName(b);
    if (gaps[i] <= std::max(tolerance, 1e-6)) {
      throw InputError(pair + " are at the same position (" + number(a.distance) +
                       " mm along the slice normal): duplicate slices (two acquisitions with one "
                       "Series Instance UID?)");
    }
    if (std::abs(gaps[i] - median) > tolerance) {
      const double k = std::round(gaps[i] / median);
      if (k >= 2 && std::abs(gaps[i] - k * median) <= tolerance * k) {
        throw InputError(pair + " are " + number(gaps[i]) + " mm apart, the slice spacing is " +
                         number(median) + " mm: " + number(k - 1) + " slice" + (k > 2 ? "s" : "") +
                         " missing between them");
      }
      throw InputError(pair + " are " + number(gaps[i]) +
                       " mm apart, but the series' median slice spacing is " + number(median) +
                       " mm (more than " + number(kGapTolerance * 100) +
                       "% different); uneven slice spacing is not supported");
    }
  }
  return median;
}

// Of the two ways along the normal, z follows the files' Instance Numbers
// when every slice has one and they strictly fall along the normal (a scanner
// going head to foot; any left-handed volume from writeDicomSeries, whose
// affine then reads back unchanged); otherwise z grows along the normal.
bool followInstanceNumbers(std::vector<Slice>& slices) {
  for (std::size_t i = 0; i < slices.size(); ++i) {
    if (!slices[i].instanceNumber) return false;
    if (i > 0 && *slices[i].instanceNumber >= *slices[i - 1].instanceNumber) return false;
  }
  std::reverse(slices.begin(), slices.end());
  return true;
}

// The slice axis is the actual step between consecutive positions. Slices
// whose positions drift within their plane by the same amount each step (a
// tilted CT gantry) make it oblique to the slices: the affine is sheared, so
// every voxel keeps its true position (nothing is resampled); the renderer
// draws the nearest orthonormal frame (PatientFrame.h).
// Positions off that straight line are an error.
void sliceStep(const std::vector<Slice>& slices, double pixel, Geometry& g) {
  const glm::dvec3 normal = glm::normalize(glm::cross(g.direction[0], g.direction[1]));
  const glm::dvec3 p0 = *slices.front().position;
  const glm::dvec3 step = (*slices.back().position - p0) / static_cast<double>(slices.size() - 1);
  for (std::size_t k = 0; k < slices.size(); ++k) {
    const glm::dvec3 off = *slices[k].position - (p0 + static_cast<double>(k) * step);
    const glm::dvec3 inPlane = off - glm::dot(off, normal) * normal;
    if (glm::length(inPlane) > kIrregularTolerancePixels * pixel) {
      throw InputError(sliceName(slices[k]) + ": position " + vecText(*slices[k].position) +
                       " is " + number(glm::length(inPlane)) +
                       " mm off the line through the first and last slice (" +
                       sliceName(slices.front()) + ", " + sliceName(slices.back()) +
                       ") within the slice plane; the slices do not form a regular stack");
    }
  }
  g.origin = p0;
  g.spacing.z = glm::length(step);
  g.direction[2] = step / g.spacing.z;
  const double along = std::abs(glm::dot(step, normal));
  const double drift = glm::length(step - glm::dot(step, normal) * normal);
  const double tiltDeg = std::atan2(drift, along) * 180.0 / 3.14159265358979323846;
  if (tiltDeg > 0.01) {
    g.notes.push_back("sheared stack: each slice is offset " + number(drift) +
                      " mm within its plane (gantry tilt " + number(tiltDeg) +
                      " deg); the affine keeps the shear");
  }
  const double declared = slices.front().spacingBetweenSlices;
  if (declared > 0 && std::abs(declared - along) > kGapTolerance * along) {
    g.notes.push_back("Spacing Between Slices says " + number(declared) + " mm, the positions " +
                      number(along) + " mm; the positions are used");
  }
}

// The LPS geometry of a checked series (PS3.3 C.7.6.2.1.1): x along the
// rows (IOP's first vector), y down the columns (its second), z from slice
// to slice in the order above; spacing x/y from Pixel Spacing (row spacing
// first, so y first), z the step between positions. Sorts `slices` into z
// order.
Geometry geometryOf(std::vector<Slice>& slices) {
  Geometry g;
  const Slice& first = slices.front();
  sliceAxes(slices, g);
  if (first.pixelSpacing) {
    g.spacing.x = first.pixelSpacing->y;
    g.spacing.y = first.pixelSpacing->x;
  } else {
    g.notes.push_back("no Pixel Spacing: 1 mm assumed");
  }
  if (slices.size() == 1) {
    singleSliceGeometry(first, g);
    return g;
  }
  sortAndCheckGaps(slices, g.direction[2]);
  if (followInstanceNumbers(slices)) g.notes.push_back("z follows Instance Number");
  sliceStep(slices, std::min(g.spacing.x, g.spacing.y), g);
  return g;
}

// Stored pixels as read from each slice, in the Volume type that holds the
// stored values exactly (signed 8-bit is widened to i16).
ScalarType storedType(const Slice& s) {
  if (s.bitsAllocated == 8) return s.isSigned ? ScalarType::I16 : ScalarType::U8;
  return s.isSigned ? ScalarType::I16 : ScalarType::U16;
}

// Values beyond Bits Stored are not part of the pixel (PS3.5 8.1.1): unsigned
// pixels are masked, signed ones sign-extended from the high bit.
template <class In, class Out>
StoredRange copyPixels(const In* in, Out* out, std::size_t n, int bitsStored, bool isSigned) {
  StoredRange r;
  const std::uint32_t mask =
      bitsStored >= 32 ? 0xffffffffu : static_cast<std::uint32_t>((1ull << bitsStored) - 1);
  const std::uint32_t signBit = 1u << (bitsStored - 1);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t raw = static_cast<std::uint32_t>(in[i]) & mask;
    std::int64_t v = raw;
    if (isSigned && (raw & signBit) != 0) v -= static_cast<std::int64_t>(mask) + 1;
    out[i] = static_cast<Out>(v);
    r.min = std::min(r.min, v);
    r.max = std::max(r.max, v);
  }
  return r;
}

}  // namespace

StoredRange storePixels(const Slice& s, const void* samples, std::uint64_t length, Volume& stored,
                        int z) {
  const std::uint64_t padding = checkPixelBytes(s, length);
  const std::size_t n = static_cast<std::size_t>(s.rows) * static_cast<std::size_t>(s.columns);
  const std::size_t at = static_cast<std::size_t>(z) * n;
  StoredRange r;
  if (s.bitsAllocated == 8) {
    const auto* p = static_cast<const std::uint8_t*>(samples);
    r = s.isSigned ? copyPixels(p, stored.dataAs<std::int16_t>() + at, n, s.bitsStored, true)
                   : copyPixels(p, stored.dataAs<std::uint8_t>() + at, n, s.bitsStored, false);
  } else {
    const auto* p = static_cast<const std::uint16_t*>(samples);
    r = s.isSigned ? copyPixels(p, stored.dataAs<std::int16_t>() + at, n, s.bitsStored, true)
                   : copyPixels(p, stored.dataAs<std::uint16_t>() + at, n, s.bitsStored, false);
  }
  r.padding = padding;
  return r;
}

std::pair<std::uint64_t, std::uint64_t> frameRange(const Slice& s, std::uint64_t length) {
  if (s.frames <= 1) return {0, length};
  const std::uint64_t frameBytes = static_cast<std::uint64_t>(s.rows) *
                                   static_cast<std::uint64_t>(s.columns) *
                                   static_cast<std::uint64_t>(s.bitsAllocated / 8);
  const std::uint64_t begin = static_cast<std::uint64_t>(s.frame) * frameBytes;
  if (begin + frameBytes > length) {
    throw InputError(sliceName(s) + ": the pixel data ends after " + std::to_string(length) +
                     " bytes, but frame " + std::to_string(s.frame + 1) + " of " +
                     std::to_string(s.frames) + " needs bytes " + std::to_string(begin) + " to " +
                     std::to_string(begin + frameBytes) +
                     " (Number of Frames says more frames than the data holds; truncated?)");
  }
  const bool last = s.frame + 1 == s.frames;
  return {begin, last ? length - begin : frameBytes};
}

namespace {

bool isInteger(double v) {
  return std::floor(v) == v && std::abs(v) < 2147483648.0;
}

// Applies each slice's slope/intercept (value = stored * slope + intercept).
// Integer slopes and intercepts keep an integer type when the values fit
// one; anything else becomes f32.
Volume rescale(Volume stored, const std::vector<Slice>& slices,
               const std::vector<StoredRange>& ranges, const std::string& what, std::string& note) {
  bool identity = true;
  bool integral = true;
  bool same = true;
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (std::size_t z = 0; z < slices.size(); ++z) {
    const Slice& s = slices[z];
    identity = identity && s.slope == 1.0 && s.intercept == 0.0;
    integral = integral && isInteger(s.slope) && isInteger(s.intercept);
    same = same && s.slope == slices[0].slope && s.intercept == slices[0].intercept;
    const double a = static_cast<double>(ranges[z].min) * s.slope + s.intercept;
    const double b = static_cast<double>(ranges[z].max) * s.slope + s.intercept;
    lo = std::min({lo, a, b});
    hi = std::max({hi, a, b});
  }
  if (identity) return stored;
  note = same ? "rescale slope " + number(slices[0].slope) + " intercept " +
                    number(slices[0].intercept) + " applied"
              : "per-slice rescale slope/intercept applied";

  ScalarType type = ScalarType::F32;
  if (integral) {
    const auto fits = [&](double min, double max) { return lo >= min && hi <= max; };
    if (fits(0, 255)) {
      type = ScalarType::U8;
    } else if (fits(-32768, 32767)) {
      type = ScalarType::I16;
    } else if (fits(0, 65535)) {
      type = ScalarType::U16;
    }
  }
  const glm::ivec3 d = stored.dims();
  Volume out = Volume::allocate(d, type, what);
  const std::size_t plane = static_cast<std::size_t>(d.x) * static_cast<std::size_t>(d.y);
  for (std::size_t z = 0; z < slices.size(); ++z) {
    const double slope = slices[z].slope;
    const double intercept = slices[z].intercept;
    for (std::size_t i = z * plane; i < (z + 1) * plane; ++i) {
      out.setValueAtIndex(i, stored.valueAtIndex(i) * slope + intercept);
    }
  }
  return out;
}

}  // namespace

void refuseEmpty(const FolderScan& scan, const std::string& what) {
  if (scan.slices.empty() && !scan.unreadable.empty()) {
    const std::size_t more = scan.unreadable.size() - 1;
    throw InputError(
        what + ": is a directory with no readable DICOM series: " + scan.unreadable.front().error +
        (more > 0 ? " (and " + std::to_string(more) + " more unreadable file(s))" : ""));
  }
  if (scan.slices.empty()) {
    std::string why;
    if (scan.nonDicomFiles == 0 && scan.nonImageObjects == 0) {
      why = "no files";
    } else {
      why = std::to_string(scan.nonDicomFiles) + " non-DICOM file(s)";
      if (scan.nonImageObjects > 0) {
        why += ", " + std::to_string(scan.nonImageObjects) + " DICOM object(s) without pixel data";
      }
    }
    if (scan.subfolders > 0) {
      why += "; " + std::to_string(scan.subfolders) +
             " subfolder(s) not searched: pass the folder of one series";
    }
    throw InputError(what + ": is a directory with no DICOM series (" + why + ")");
  }
}

namespace {

// The volume's index -> world affine: LPS converted to RAS (PatientFrame.h).
void applyGeometry(const Geometry& g, Volume& v) {
  v.setSpacing(g.spacing);
  v.setDirection(lpsToRas() * g.direction);
  v.setOrigin(lpsToRas() * g.origin);
  v.setGeometrySource(g.source);
}

// The series' own window (Window Center/Width, PS3.3 C.11.2.1.2, already in
// rescaled units) becomes the volume's window, so that classification
// starts where the scanner's operator left it; its linear-exact form
// [c - w/2, c + w/2] is used (the DICOM "linear" function differs by half a
// stored step, nothing a transfer function can show).
void applySeriesWindow(const Slice& s, Volume& v, std::vector<std::string>& notes) {
  if (!s.windowCenter || !s.windowWidth) return;
  const double c = *s.windowCenter;
  const double w = *s.windowWidth;
  v.setWindow({c - 0.5 * w, c + 0.5 * w});
  notes.push_back("window " + number(c) + "/" + number(w) + " (centre/width) from the series");
}

// The series picked from a folder scan, with what was set aside on the way.
struct PickedSeries {
  std::vector<Slice> slices;
  std::string label;        // the whole group's, for the description
  std::size_t index = 0;    // among `groups`
  std::size_t leftOut = 0;  // slices of the group outside the named file's stack
  std::vector<UnreadableFile> unreadableMembers;    // skipped copies of slices read
  std::vector<UnreadableFile> unreadableElsewhere;  // other or unknown series
};

// Picks the series `seriesUid` (empty: the one holding `named`, else the
// largest) and judges the files of it that could not be used.
PickedSeries pickSeries(std::vector<SeriesGroup>& groups, std::vector<UnreadableFile> unreadable,
                        const std::string& seriesUid, const fs::path& named,
                        const std::string& what) {
  PickedSeries p;
  p.index = chooseGroup(groups, seriesUid, named, what);
  SeriesGroup& g = groups[p.index];
  p.label = g.label();
  p.slices = std::move(g.slices);  // othersText() skips this group
  p.leftOut = keepStackOf(p.slices, named);
  for (auto& u : unreadable) {
    const bool member = !g.uid.empty() && u.seriesUid == g.uid;
    (member ? p.unreadableMembers : p.unreadableElsewhere).push_back(std::move(u));
  }
  checkUnreadableMembers(p.unreadableMembers, p.slices);
  return p;
}

// Decodes every slice (in z order) and applies rescale slope/intercept.
Volume readVoxels(const std::vector<Slice>& slices, const std::string& what,
                  const PixelDecoder& decode, std::vector<std::string>& notes) {
  const Slice& first = slices.front();
  const glm::ivec3 dims(first.columns, first.rows, static_cast<int>(slices.size()));
  // Volume::allocate checks the host budget before any pixel is decoded.
  Volume stored = Volume::allocate(dims, storedType(first), what);
  std::vector<StoredRange> ranges;
  ranges.reserve(slices.size());
  for (std::size_t z = 0; z < slices.size(); ++z) {
    ranges.push_back(decode(slices[z], stored, static_cast<int>(z)));
  }
  std::string rescaleNote;
  Volume v = rescale(std::move(stored), slices, ranges, what, rescaleNote);
  v.invalidateRange();
  if (!rescaleNote.empty()) notes.push_back(rescaleNote);
  const auto padded = std::count_if(ranges.begin(), ranges.end(),
                                    [](const StoredRange& r) { return r.padding > 1; });
  if (padded > 0) {
    notes.push_back("ignored trailing padding after the pixel data of " + std::to_string(padded) +
                    " file(s)");
  }
  return v;
}

// What was skipped or left out, one note each.
void addSkipNotes(const PickedSeries& p, const FolderScan& scan, const fs::path& named,
                  std::vector<std::string>& notes) {
  if (p.slices.front().photometric == "MONOCHROME1") {
    notes.push_back("MONOCHROME1: low values display bright");
  }
  if (p.leftOut > 0) {
    notes.push_back("left out " + std::to_string(p.leftOut) +
                    " file(s) of this series with another size, frame count, pixel type, "
                    "orientation or pixel spacing than " +
                    named.string());
  }
  if (scan.nonDicomFiles > 0) {
    notes.push_back("skipped " + std::to_string(scan.nonDicomFiles) + " non-DICOM file(s)");
  }
  if (!p.unreadableMembers.empty()) {
    notes.push_back("skipped " + std::to_string(p.unreadableMembers.size()) +
                    " unreadable file(s) of this series as copies of slices read (same or no "
                    "position), e.g. " +
                    p.unreadableMembers.front().error);
  }
  if (!p.unreadableElsewhere.empty()) {
    notes.push_back("skipped " + std::to_string(p.unreadableElsewhere.size()) +
                    " unreadable DICOM file(s) of other or unknown series, e.g. " +
                    p.unreadableElsewhere.front().error);
  }
}

// The series picked from `scan`, checked, decoded and described; `lead`
// notes come first in the description.
Volume assembleSeries(FolderScan scan, const std::string& seriesUid, const std::string& what,
                      const PixelDecoder& decode, const fs::path& named,
                      std::vector<std::string> lead = {}) {
  refuseEmpty(scan, what);
  std::vector<SeriesGroup> groups = groupSeries(std::move(scan.slices));
  PickedSeries p = pickSeries(groups, std::move(scan.unreadable), seriesUid, named, what);
  for (const auto& s : p.slices) checkSlice(s);
  checkConsistent(p.slices);
  const Geometry g = geometryOf(p.slices);
  std::vector<std::string> notes = std::move(lead);
  notes.insert(notes.end(), g.notes.begin(), g.notes.end());
  Volume v = readVoxels(p.slices, what, decode, notes);
  applyGeometry(g, v);
  applySeriesWindow(p.slices.front(), v, notes);
  v.setModality(p.slices.front().modality);  // the session's default TF follows it
  addSkipNotes(p, scan, named, notes);

  std::string d = "DICOM series " + p.label + ", " + p.slices.front().transferSyntax + "; series " +
                  std::to_string(p.index + 1) + " of " + std::to_string(groups.size()) + " in " +
                  scan.where;
  if (groups.size() > 1) d += "; others: " + othersText(groups, p.index);
  for (const auto& n : notes) d += "; " + n;
  v.setDescription(d);
  return v;
}

// Why a named file cannot take a place in its series, for the note that
// says it is read alone: other files of its stack at its position (copies,
// other encodings of the same slice: pydicom's test files share a Series
// Instance UID), or no Image Position (Patient) to order it among them.
// nullopt when it can (the series is then read, or refused naming the file
// at fault), or when nothing of its stack is beside it.
std::optional<std::string> cannotHold(const Slice& own, const std::vector<Slice>& slices,
                                      const std::string& what) {
  std::size_t stack = 0;
  const Slice* copy = nullptr;
  std::size_t copies = 0;
  for (const Slice& s : slices) {
    if (s.file == own.file || s.seriesUid != own.seriesUid || !sameStack(s, own)) continue;
    ++stack;
    if (own.position && s.position && glm::length(*s.position - *own.position) <= kSamePositionMm) {
      if (copies++ == 0) copy = &s;
    }
  }
  if (stack == 0) return std::nullopt;
  if (!own.position) {
    return what + ": read alone: it has no Image Position (Patient) (0020,0032), so the " +
           std::to_string(stack) + " other file" + (stack == 1 ? "" : "s") +
           " of its series cannot be ordered with it";
  }
  if (copies == 0) return std::nullopt;
  return what + ": read alone: " + std::to_string(copies) + " other file" +
         (copies == 1 ? " of its series is" : "s of its series are") +
         " at its position (duplicate slices, e.g. " + copy->file.string() +
         "), so the series around it was not assembled";
}

}  // namespace

Volume readSeries(FolderScan scan, const std::string& seriesUid, const std::string& what,
                  const PixelDecoder& decode, const fs::path& named) {
  const auto own = std::find_if(scan.slices.begin(), scan.slices.end(),
                                [&](const Slice& s) { return !named.empty() && s.file == named; });
  // Files given as a folder or a list are one series or an error.
  if (own == scan.slices.end()) {
    return assembleSeries(std::move(scan), seriesUid, what, decode, named);
  }
  // A file named on its own that its series cannot hold is what the user
  // wants to see: it is read as if alone in its folder, with a note, rather
  // than refused for its neighbours; its own errors still refuse it. A
  // series asked for by UID is that series or an error.
  if (seriesUid.empty()) {
    if (const auto note = cannotHold(*own, scan.slices, what)) {
      FolderScan alone;
      alone.where = "file " + what + " (alone)";
      alone.slices.push_back(*own);
      Volume v = assembleSeries(std::move(alone), "", what, decode, named, {*note});
      // One slice instead of the series the user may expect is said where
      // it is seen, not only in the description.
      std::fprintf(stderr, "note: %s\n", note->c_str());
      return v;
    }
  }
  // Otherwise a series that cannot be read (a broken, missing or misplaced
  // slice) is an error, never a volume short of a slice; it names the file
  // at fault and, when that is another, the file the user gave.
  try {
    return assembleSeries(std::move(scan), seriesUid, what, decode, named);
  } catch (const InputError& e) {
    const std::string m = e.what();
    if (m.find(named.string()) != std::string::npos || m.find(what) != std::string::npos) throw;
    throw InputError(what + ": " + (seriesUid.empty() ? "its series" : "series " + seriesUid) +
                     " cannot be read from the files beside it: " + m);
  }
}

std::vector<DicomSeriesInfo> listSeries(FolderScan scan) {
  std::vector<DicomSeriesInfo> out;
  for (const auto& g : groupSeries(std::move(scan.slices))) {
    const Slice& s = g.slices.front();
    std::string d = s.seriesDescription;
    if (!s.modality.empty()) d += (d.empty() ? "" : ", ") + s.modality;
    out.push_back({g.uid, d, static_cast<int>(g.slices.size()), g.severalStacks ? g.stack : ""});
  }
  return out;
}

namespace {
fs::path folderOf(const fs::path& p) {
  fs::path f = p.parent_path();
  return f.empty() ? fs::path(".") : f;
}
}  // namespace

FolderScan scanFolder(const fs::path& folder, const FileAdder& add) {
  FolderScan scan;
  scan.where = "folder " + folder.string();
  std::vector<fs::path> files;
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code tec;
    if (it->is_directory(tec)) {
      ++scan.subfolders;
    } else if (it->is_regular_file(tec)) {
      files.push_back(it->path());
    }
  }
  if (ec) throw InputError(folder.string() + ": cannot list the folder: " + ec.message());
  // Sorted only so that messages are the same from run to run; slice order
  // comes from positions.
  std::sort(files.begin(), files.end());
  for (const auto& f : files) add(f, false, scan);
  return scan;
}

Volume readFolderOrFile(const fs::path& folderOrFile, const std::string& seriesUid,
                        const FileAdder& add, const PixelDecoder& decode) {
  const std::string p = folderOrFile.string();
  std::error_code ec;
  const fs::file_status st = fs::status(folderOrFile, ec);
  if (ec || !fs::exists(st)) throw InputError(p + ": no such file or directory");
  if (fs::is_directory(st)) return readSeries(scanFolder(folderOrFile, add), seriesUid, p, decode);
  if (!fs::is_regular_file(st)) throw InputError(p + ": not a regular file or a directory");

  // One file: its own errors first, then its series (and stack) from the
  // files beside it, or the file alone when its series cannot hold it.
  FolderScan own;
  add(folderOrFile, true, own);
  const fs::path folder = folderOf(folderOrFile);
  return readSeries(scanFolder(folder, add), seriesUid, p, decode,
                    folder / folderOrFile.filename());
}

std::vector<DicomSeriesInfo> listFolderSeries(const fs::path& folder, const FileAdder& add) {
  std::error_code ec;
  const fs::path dir = fs::is_directory(folder, ec) ? folder : folderOf(folder);
  if (!fs::is_directory(dir, ec)) throw InputError(folder.string() + ": no such directory");
  return listSeries(scanFolder(dir, add));
}

}  // namespace tessera::io_detail
