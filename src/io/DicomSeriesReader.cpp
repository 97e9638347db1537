// DICOM series → one volume (Schultz 2016, 6.1 and 7.1.1), through DCMTK.
// Attribute meanings follow DICOM PS3.3 C.7.6.2 (Image Plane module: position,
// orientation, pixel spacing) and C.7.6.3 (Image Pixel module: rows, columns,
// bits, pixel representation); rescale follows C.11.1.1.2.
#include "tessera/io/DicomSeriesReader.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include "io/DicomToolkit.h"
#include "tessera/core/Error.h"

#include <dcmtk/dcmdata/dcdatset.h>
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcmetinf.h>
#include <dcmtk/dcmdata/dcstack.h>

namespace tessera {

namespace fs = std::filesystem;
using io_detail::conditionText;
using io_detail::transferSyntaxText;

namespace {

// Direction cosines of two slices agree when every component is within this.
constexpr double kOrientationTolerance = 1e-3;
// Consecutive slice gaps may differ from the median gap by this fraction.
constexpr double kGapTolerance = 0.01;
// Largest in-plane drift of slice positions, in pixels, still read as a stack.
constexpr double kShearTolerancePixels = 0.5;

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

// One image file of a series: what the header says, before any pixel is read.
struct Slice {
  fs::path file;
  std::string seriesUid;
  std::string seriesDescription;
  std::string modality;
  E_TransferSyntax xfer = EXS_Unknown;
  int rows = 0;
  int columns = 0;
  int bitsAllocated = 0;
  int bitsStored = 0;
  int highBit = -1;
  bool isSigned = false;
  int samplesPerPixel = 1;
  long frames = 1;
  std::string photometric;
  std::optional<glm::dvec3> position;
  std::optional<glm::dvec3> rowDir;        // direction of increasing column index
  std::optional<glm::dvec3> colDir;        // direction of increasing row index
  std::optional<glm::dvec2> pixelSpacing;  // (between rows, between columns)
  double slope = 1.0;
  double intercept = 0.0;
  double sliceThickness = 0.0;
  double spacingBetweenSlices = 0.0;
  // Declared length of uncompressed pixel data, checked before anything is
  // allocated (compressed data is checked once decoded).
  std::optional<std::uint64_t> pixelBytes;
  // The first malformed attribute, reported only if this slice is read.
  std::string defect;
  double distance = 0.0;  // along the slice normal, set when sorting
};

struct FolderScan {
  std::string where;  // "folder X" or "the N files given"
  std::vector<Slice> slices;
  int nonDicomFiles = 0;
  int nonImageObjects = 0;  // DICOMDIR, reports, ... (no Pixel Data)
  // Part-10 files DCMTK cannot parse (truncated, unknown syntax): an error if
  // they belong to the series read (or nothing else is readable), a note if
  // they belong to another one.
  struct Unreadable {
    std::string error;
    std::string seriesUid;  // as far as the file could be parsed; may be empty
  };
  std::vector<Unreadable> unreadable;
  int subfolders = 0;
};

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
// file, so an element that says otherwise marks the file corrupt.
void checkDeclaredLengths(DcmItem& item, const fs::path& file, std::uintmax_t fileSize) {
  DcmStack stack;
  while (item.nextObject(stack, OFTrue).good()) {
    DcmObject* obj = stack.top();
    if (obj == nullptr || !obj->isLeaf()) continue;
    const Uint32 declared = obj->getLengthField();
    if (declared == DCM_UndefinedLength || declared <= fileSize) continue;
    DcmTag tag = obj->getTag();
    throw InputError(file.string() + ": element " + tag.toString().c_str() + " " +
                     tag.getTagName() + " declares " + std::to_string(declared) +
                     " bytes but the file has only " + std::to_string(fileSize) +
                     " (corrupt file)");
  }
}

// Loads `file` (large values, i.e. the pixel data, stay on disk until used).
// False when the file is not DICOM; InputError for a Part-10 file that DCMTK
// cannot parse (truncated, corrupt, unknown transfer syntax) or whose
// elements declare more bytes than the file holds.
bool loadDicom(const fs::path& file, DcmFileFormat& ff) {
  const Probe probe = probeFile(file);
  if (probe == Probe::NotDicom) return false;
  std::error_code ec;
  const std::uintmax_t fileSize = fs::file_size(file, ec);
  if (ec) throw InputError(file.string() + ": cannot read: " + ec.message());
  const OFCondition c = ff.loadFile(file.c_str(), EXS_Unknown, EGL_noChange, DCM_MaxReadLength,
                                    probe == Probe::Part10 ? ERM_fileOnly : ERM_dataset);
  if (c.good()) {
    if (ff.getMetaInfo() != nullptr) checkDeclaredLengths(*ff.getMetaInfo(), file, fileSize);
    checkDeclaredLengths(*ff.getDataset(), file, fileSize);
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

// The text of a short attribute, "" when absent. The declared length is
// checked first: this also runs on files that failed to load, whose lengths
// nobody has vetted (see checkDeclaredLengths).
std::string stringAttr(DcmItem& ds, const DcmTagKey& tag) {
  constexpr Uint32 kLongestAttribute = 64 * 1024;  // LT holds 10240 characters
  DcmElement* elem = nullptr;
  if (ds.findAndGetElement(tag, elem).bad() || elem == nullptr ||
      elem->getLengthField() > kLongestAttribute) {
    return "";
  }
  OFString s;
  if (elem->getOFStringArray(s).bad()) return "";
  std::string r = s.c_str();
  const auto b = r.find_first_not_of(' ');
  const auto e = r.find_last_not_of(' ');
  return b == std::string::npos ? "" : r.substr(b, e - b + 1);
}

// Reads the attributes a slice needs; problems are recorded in `defect`, not
// thrown, so that a broken file of a series nobody asked for does no harm.
Slice sliceHeader(const fs::path& file, DcmFileFormat& ff) {
  DcmDataset& ds = *ff.getDataset();
  Slice s;
  s.file = file;
  s.xfer = ds.getOriginalXfer();
  s.seriesUid = stringAttr(ds, DCM_SeriesInstanceUID);
  s.seriesDescription = stringAttr(ds, DCM_SeriesDescription);
  s.modality = stringAttr(ds, DCM_Modality);
  s.photometric = stringAttr(ds, DCM_PhotometricInterpretation);

  auto defect = [&](const std::string& msg) {
    if (s.defect.empty()) s.defect = msg;
  };
  auto u16 = [&](const DcmTagKey& tag, const char* name, int& out, bool required) {
    Uint16 v = 0;
    if (ds.findAndGetUint16(tag, v).good()) {
      out = v;
    } else if (required) {
      defect(std::string("has no ") + name + " " + DcmTag(tag).getTagName());
    }
  };
  u16(DCM_Rows, "Rows", s.rows, true);
  u16(DCM_Columns, "Columns", s.columns, true);
  u16(DCM_BitsAllocated, "Bits Allocated", s.bitsAllocated, true);
  s.bitsStored = s.bitsAllocated;
  u16(DCM_BitsStored, "Bits Stored", s.bitsStored, false);
  s.highBit = s.bitsStored - 1;
  u16(DCM_HighBit, "High Bit", s.highBit, false);
  u16(DCM_SamplesPerPixel, "Samples per Pixel", s.samplesPerPixel, false);
  int pixelRepresentation = 0;
  u16(DCM_PixelRepresentation, "Pixel Representation", pixelRepresentation, false);
  s.isSigned = pixelRepresentation == 1;

  DcmElement* pixels = nullptr;
  if (!DcmXfer(s.xfer).isEncapsulated() && ds.findAndGetElement(DCM_PixelData, pixels).good() &&
      pixels != nullptr) {
    s.pixelBytes = pixels->getLength();
  }

  Sint32 frames = 1;
  if (ds.findAndGetSint32(DCM_NumberOfFrames, frames).good()) s.frames = frames;

  // Decimal strings: absent is fine (nullopt), present but malformed is a defect.
  auto numbers = [&](const DcmTagKey& tag, const char* name,
                     unsigned long count) -> std::optional<std::vector<double>> {
    DcmElement* elem = nullptr;
    if (ds.findAndGetElement(tag, elem).bad() || elem == nullptr || elem->getLength() == 0) {
      return std::nullopt;
    }
    std::vector<double> v(count);
    for (unsigned long i = 0; i < count; ++i) {
      Float64 x = 0;
      if (ds.findAndGetFloat64(tag, x, i).bad() || !std::isfinite(x)) {
        defect(std::string(name) + " " + DcmTag(tag).getTagName() + " is " +
               quoted(stringAttr(ds, tag)) + ", expected " + std::to_string(count) + " numbers");
        return std::nullopt;
      }
      v[i] = x;
    }
    return v;
  };
  if (auto p = numbers(DCM_ImagePositionPatient, "Image Position (Patient)", 3)) {
    s.position = glm::dvec3((*p)[0], (*p)[1], (*p)[2]);
  }
  if (auto o = numbers(DCM_ImageOrientationPatient, "Image Orientation (Patient)", 6)) {
    const glm::dvec3 r((*o)[0], (*o)[1], (*o)[2]);
    const glm::dvec3 c((*o)[3], (*o)[4], (*o)[5]);
    if (glm::length(r) < 0.5 || glm::length(c) < 0.5 ||
        std::abs(glm::dot(glm::normalize(r), glm::normalize(c))) > kOrientationTolerance) {
      defect("Image Orientation (Patient) " + vecText(r) + " " + vecText(c) +
             " is not two perpendicular unit vectors");
    } else {
      s.rowDir = glm::normalize(r);
      s.colDir = glm::normalize(c);
    }
  }
  if (auto p = numbers(DCM_PixelSpacing, "Pixel Spacing", 2)) {
    if ((*p)[0] <= 0 || (*p)[1] <= 0) {
      defect("Pixel Spacing is " + number((*p)[0]) + "\\" + number((*p)[1]) +
             ", expected two positive numbers");
    } else {
      s.pixelSpacing = glm::dvec2((*p)[0], (*p)[1]);
    }
  }
  if (auto v = numbers(DCM_RescaleSlope, "Rescale Slope", 1)) {
    if ((*v)[0] == 0.0) defect("Rescale Slope is 0");
    s.slope = (*v)[0];
  }
  if (auto v = numbers(DCM_RescaleIntercept, "Rescale Intercept", 1)) s.intercept = (*v)[0];
  if (auto v = numbers(DCM_SliceThickness, "Slice Thickness", 1)) s.sliceThickness = (*v)[0];
  if (auto v = numbers(DCM_SpacingBetweenSlices, "Spacing Between Slices", 1)) {
    s.spacingBetweenSlices = (*v)[0];
  }
  return s;
}

void addFile(const fs::path& file, bool mustBeImage, FolderScan& scan) {
  DcmFileFormat ff;
  bool isDicom = false;
  try {
    isDicom = loadDicom(file, ff);
  } catch (const InputError& e) {
    if (mustBeImage) throw;
    // What was parsed before the failure usually includes the series UID.
    scan.unreadable.push_back({e.what(), stringAttr(*ff.getDataset(), DCM_SeriesInstanceUID)});
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
  if (!ff.getDataset()->tagExists(DCM_PixelData)) {
    if (mustBeImage) {
      throw InputError(file.string() + ": a DICOM object without Pixel Data (7FE0,0010) (" +
                       stringAttr(*ff.getDataset(), DCM_Modality) + "); not an image");
    }
    ++scan.nonImageObjects;
    return;
  }
  scan.slices.push_back(sliceHeader(file, ff));
}

FolderScan scanFolder(const fs::path& folder) {
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
  for (const auto& f : files) addFile(f, false, scan);
  return scan;
}

struct SeriesGroup {
  std::string uid;
  std::vector<Slice> slices;
  std::string label() const {
    const Slice& s = slices.front();
    std::string t = uid.empty() ? "(no Series Instance UID)" : uid;
    t += " (" + std::to_string(slices.size()) + " slice" + (slices.size() == 1 ? "" : "s");
    if (!s.modality.empty()) t += ", " + s.modality;
    if (!s.seriesDescription.empty()) t += ", \"" + s.seriesDescription + "\"";
    return t + ")";
  }
};

// Series by Series Instance UID, the largest first.
std::vector<SeriesGroup> groupSeries(std::vector<Slice> slices) {
  std::map<std::string, std::vector<Slice>> byUid;
  for (auto& s : slices) byUid[s.seriesUid].push_back(std::move(s));
  std::vector<SeriesGroup> groups;
  for (auto& [uid, v] : byUid) groups.push_back({uid, std::move(v)});
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

// Pixel data must hold Rows x Columns pixels; one byte of padding keeps odd
// lengths even (PS3.5 8.1.1).
void checkPixelBytes(const Slice& s, std::uint64_t length) {
  const std::uint64_t bytes = static_cast<std::uint64_t>(s.bitsAllocated / 8);
  const std::uint64_t expected =
      static_cast<std::uint64_t>(s.rows) * static_cast<std::uint64_t>(s.columns) * bytes;
  if (length < expected || length > expected + 1) {
    throw InputError(s.file.string() + ": pixel data has " + std::to_string(length) +
                     " bytes, but " + std::to_string(s.columns) + "x" + std::to_string(s.rows) +
                     " pixels x " + std::to_string(bytes) + " bytes = " + std::to_string(expected) +
                     " bytes" + (length < expected ? " (truncated)" : " (more than one frame?)"));
  }
}

// Checks one slice on its own: what any single file must satisfy to be read.
void checkSlice(const Slice& s) {
  const std::string f = s.file.string();
  if (!s.defect.empty()) throw InputError(f + ": " + s.defect);
  if (s.frames > 1) {
    throw InputError(f + ": Number of Frames is " + std::to_string(s.frames) +
                     "; multi-frame not supported (only one image per file)");
  }
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
  if (s.pixelBytes) checkPixelBytes(s, *s.pixelBytes);
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
      throw InputError(s.file.string() + ": Rows x Columns is " + std::to_string(s.rows) + "x" +
                       std::to_string(s.columns) + ", but the other slices of the series (e.g. " +
                       ref->file.string() + ") are " + std::to_string(ref->rows) + "x" +
                       std::to_string(ref->columns));
    }
    if (s.bitsAllocated != ref->bitsAllocated || s.isSigned != ref->isSigned) {
      throw InputError(s.file.string() + ": " + std::to_string(s.bitsAllocated) + "-bit " +
                       (s.isSigned ? "signed" : "unsigned") + " pixels, but " + ref->file.string() +
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
      throw InputError(s.file.string() + ": Pixel Spacing is " + text(s) + ", but " +
                       ref->file.string() + " has " + text(*ref));
    }
  }
}

struct Geometry {
  glm::dvec3 rowDir{1, 0, 0};
  glm::dvec3 colDir{0, 1, 0};
  glm::dvec3 normal{0, 0, 1};
  double sliceSpacing = 1.0;
  std::string note;  // assumptions made, for the description
};

// Sorts `slices` along the normal and derives the slice spacing; throws for
// mixed orientations, duplicate positions, missing slices and uneven gaps.
Geometry sortAlongNormal(std::vector<Slice>& slices) {
  Geometry g;
  const Slice& first = slices.front();
  if (slices.size() == 1) {
    if (first.rowDir) {
      g.rowDir = *first.rowDir;
      g.colDir = *first.colDir;
      g.normal = glm::normalize(glm::cross(g.rowDir, g.colDir));
    }
    if (first.spacingBetweenSlices > 0) {
      g.sliceSpacing = first.spacingBetweenSlices;
    } else if (first.sliceThickness > 0) {
      g.sliceSpacing = first.sliceThickness;
    } else {
      g.note = "one slice without Slice Thickness: z spacing assumed 1";
    }
    return g;
  }
  for (const auto& s : slices) {
    if (!s.position || !s.rowDir) {
      throw InputError(s.file.string() + ": no " +
                       (s.position ? "Image Orientation (Patient) (0020,0037)"
                                   : "Image Position (Patient) (0020,0032)") +
                       "; the slices of a series cannot be ordered without it");
    }
  }
  g.rowDir = *first.rowDir;
  g.colDir = *first.colDir;
  for (const auto& s : slices) {
    const glm::dvec3 dr = *s.rowDir - g.rowDir;
    const glm::dvec3 dc = *s.colDir - g.colDir;
    const double worst = std::max({std::abs(dr.x), std::abs(dr.y), std::abs(dr.z), std::abs(dc.x),
                                   std::abs(dc.y), std::abs(dc.z)});
    if (worst > kOrientationTolerance) {
      throw InputError(s.file.string() + ": Image Orientation (Patient) is " + vecText(*s.rowDir) +
                       " " + vecText(*s.colDir) + ", but " + first.file.string() + " has " +
                       vecText(g.rowDir) + " " + vecText(g.colDir) +
                       "; slices of one volume must share an orientation");
    }
  }
  g.normal = glm::normalize(glm::cross(g.rowDir, g.colDir));
  for (auto& s : slices) s.distance = glm::dot(*s.position, g.normal);
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
    const std::string pair = a.file.string() + " and " + b.file.string();
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
  // A stack along the normal: positions must not drift within the slice
  // plane (a tilted gantry shears the volume, which a Volume cannot hold).
  const double pixel =
      first.pixelSpacing ? std::min(first.pixelSpacing->x, first.pixelSpacing->y) : 1.0;
  for (const auto& s : slices) {
    const glm::dvec3 d = *s.position - *slices.front().position;
    const glm::dvec3 inPlane = d - glm::dot(d, g.normal) * g.normal;
    if (glm::length(inPlane) > kShearTolerancePixels * pixel) {
      throw InputError(s.file.string() + ": position " + vecText(*s.position) + " is offset by " +
                       number(glm::length(inPlane)) + " mm within the slice plane from " +
                       slices.front().file.string() +
                       " (gantry tilt?); sheared series are not supported");
    }
  }
  g.sliceSpacing = median;
  return g;
}

// Stored pixels as read from each slice, in the Volume type that holds the
// stored values exactly (signed 8-bit is widened to i16).
ScalarType storedType(const Slice& s) {
  if (s.bitsAllocated == 8) return s.isSigned ? ScalarType::I16 : ScalarType::U8;
  return s.isSigned ? ScalarType::I16 : ScalarType::U16;
}

struct StoredRange {
  std::int64_t min = std::numeric_limits<std::int64_t>::max();
  std::int64_t max = std::numeric_limits<std::int64_t>::min();
};

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

// Decodes one slice's pixels into z-plane `z` of `stored`.
StoredRange readPixels(const Slice& s, Volume& stored, int z) {
  const std::string f = s.file.string();
  DcmFileFormat ff;
  if (!loadDicom(s.file, ff)) throw InputError(f + ": is no longer a DICOM file");
  DcmDataset& ds = *ff.getDataset();
  const E_TransferSyntax xfer = ds.getOriginalXfer();
  if (DcmXfer(xfer).isEncapsulated()) {
    const OFCondition c = ds.chooseRepresentation(EXS_LittleEndianExplicit, nullptr);
    if (c.bad() || !ds.canWriteXfer(EXS_LittleEndianExplicit)) {
      throw InputError(f + ": transfer syntax " + transferSyntaxText(xfer) +
                       " cannot be decoded (DCMTK: " + conditionText(c) +
                       "); supported: uncompressed, deflate, JPEG baseline/extended/lossless, "
                       "JPEG-LS and RLE");
    }
  }
  DcmElement* elem = nullptr;
  if (ds.findAndGetElement(DCM_PixelData, elem).bad() || elem == nullptr) {
    throw InputError(f + ": no Pixel Data (7FE0,0010)");
  }
  const std::size_t n = static_cast<std::size_t>(s.rows) * static_cast<std::size_t>(s.columns);
  checkPixelBytes(s, elem->getLength());
  const std::size_t planeOffset = static_cast<std::size_t>(z) * n;
  const auto loadFailed = [&](const OFCondition& c) {
    return InputError(f + ": pixel data cannot be read (DCMTK: " + conditionText(c) +
                      "; truncated file?)");
  };
  if (s.bitsAllocated == 8) {
    Uint8* p = nullptr;
    const OFCondition c = elem->getUint8Array(p);
    if (c.bad() || p == nullptr) throw loadFailed(c);
    if (s.isSigned) {
      return copyPixels(p, stored.dataAs<std::int16_t>() + planeOffset, n, s.bitsStored, true);
    }
    return copyPixels(p, stored.dataAs<std::uint8_t>() + planeOffset, n, s.bitsStored, false);
  }
  Uint16* p = nullptr;
  const OFCondition c = elem->getUint16Array(p);
  if (c.bad() || p == nullptr) throw loadFailed(c);
  if (s.isSigned) {
    return copyPixels(p, stored.dataAs<std::int16_t>() + planeOffset, n, s.bitsStored, true);
  }
  return copyPixels(p, stored.dataAs<std::uint16_t>() + planeOffset, n, s.bitsStored, false);
}

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

Volume readSeries(FolderScan scan, const std::string& seriesUid, const std::string& what) {
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
  std::vector<SeriesGroup> groups = groupSeries(std::move(scan.slices));
  std::size_t chosen = 0;
  if (!seriesUid.empty()) {
    const auto it = std::find_if(groups.begin(), groups.end(),
                                 [&](const SeriesGroup& g) { return g.uid == seriesUid; });
    if (it == groups.end()) {
      throw InputError(what + ": no series with Series Instance UID " + seriesUid +
                       "; found: " + othersText(groups, groups.size()));
    }
    chosen = static_cast<std::size_t>(it - groups.begin());
  }
  std::vector<Slice>& slices = groups[chosen].slices;
  int unreadableElsewhere = 0;
  for (const auto& u : scan.unreadable) {
    if (u.seriesUid == groups[chosen].uid) throw InputError(u.error);
    ++unreadableElsewhere;
  }
  for (const auto& s : slices) checkSlice(s);
  checkConsistent(slices);
  const Geometry g = sortAlongNormal(slices);

  const Slice& first = slices.front();
  const glm::ivec3 dims(first.columns, first.rows, static_cast<int>(slices.size()));
  // Volume::allocate checks the host budget before any pixel is decoded.
  Volume stored = Volume::allocate(dims, storedType(first), what);
  std::vector<StoredRange> ranges;
  ranges.reserve(slices.size());
  for (std::size_t z = 0; z < slices.size(); ++z) {
    ranges.push_back(readPixels(slices[z], stored, static_cast<int>(z)));
  }
  std::string rescaleNote;
  Volume v = rescale(std::move(stored), slices, ranges, what, rescaleNote);
  v.invalidateRange();

  // PixelSpacing is (row spacing, column spacing): y first (PS3.3 10.7.1.3).
  glm::dvec3 spacing(1.0, 1.0, g.sliceSpacing);
  std::vector<std::string> notes;
  if (first.pixelSpacing) {
    spacing.x = first.pixelSpacing->y;
    spacing.y = first.pixelSpacing->x;
  } else {
    notes.push_back("no Pixel Spacing: 1 mm assumed");
  }
  if (!g.note.empty()) notes.push_back(g.note);
  v.setSpacing(spacing);
  if (first.position) v.setOrigin(*first.position);

  std::string d = "DICOM series " + groups[chosen].label() + ", " + transferSyntaxText(first.xfer);
  d += "; series " + std::to_string(chosen + 1) + " of " + std::to_string(groups.size()) + " in " +
       scan.where;
  if (groups.size() > 1) d += "; others: " + othersText(groups, chosen);
  if (!rescaleNote.empty()) notes.push_back(rescaleNote);
  if (first.photometric == "MONOCHROME1") notes.push_back("MONOCHROME1: low values display bright");
  if (glm::length(g.rowDir - glm::dvec3(1, 0, 0)) > kOrientationTolerance ||
      glm::length(g.colDir - glm::dvec3(0, 1, 0)) > kOrientationTolerance) {
    notes.push_back("volume axes follow the slices: x " + vecText(g.rowDir) + ", y " +
                    vecText(g.colDir) + ", z " + vecText(g.normal) + " in patient space");
  }
  if (scan.nonDicomFiles > 0) {
    notes.push_back("skipped " + std::to_string(scan.nonDicomFiles) + " non-DICOM file(s)");
  }
  if (unreadableElsewhere > 0) {
    notes.push_back("skipped " + std::to_string(unreadableElsewhere) +
                    " unreadable DICOM file(s) of other or unknown series, e.g. " +
                    scan.unreadable.front().error);
  }
  for (const auto& n : notes) d += "; " + n;
  v.setDescription(d);
  return v;
}

fs::path folderOf(const fs::path& p) {
  fs::path f = p.parent_path();
  return f.empty() ? fs::path(".") : f;
}

}  // namespace

Volume readDicomSeries(const fs::path& folderOrFile, const std::string& seriesUid) {
  io_detail::initDicomToolkit();
  const std::string p = folderOrFile.string();
  std::error_code ec;
  const fs::file_status st = fs::status(folderOrFile, ec);
  if (ec || !fs::exists(st)) throw InputError(p + ": no such file or directory");
  if (fs::is_directory(st)) return readSeries(scanFolder(folderOrFile), seriesUid, p);
  if (!fs::is_regular_file(st)) throw InputError(p + ": not a regular file or a directory");

  // One file: the series it belongs to, from the files beside it.
  FolderScan own;
  addFile(folderOrFile, true, own);
  const std::string uid = seriesUid.empty() ? own.slices.front().seriesUid : seriesUid;
  FolderScan scan = scanFolder(folderOf(folderOrFile));
  return readSeries(std::move(scan), uid, p);
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
  return readSeries(std::move(scan), seriesUid, files.front().string());
}

std::vector<DicomSeriesInfo> listDicomSeries(const fs::path& folder) {
  io_detail::initDicomToolkit();
  std::error_code ec;
  const fs::path dir = fs::is_directory(folder, ec) ? folder : folderOf(folder);
  if (!fs::is_directory(dir, ec)) throw InputError(folder.string() + ": no such directory");
  FolderScan scan = scanFolder(dir);
  std::vector<DicomSeriesInfo> out;
  for (const auto& g : groupSeries(std::move(scan.slices))) {
    const Slice& s = g.slices.front();
    std::string d = s.seriesDescription;
    if (!s.modality.empty()) d += (d.empty() ? "" : ", ") + s.modality;
    out.push_back({g.uid, d, static_cast<int>(g.slices.size())});
  }
  return out;
}

}  // namespace tessera
