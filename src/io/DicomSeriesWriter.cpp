// Volume → a series of single-frame DICOM files (CT or MR Image Storage),
// through DCMTK. Modules after DICOM PS3.3 A.3 (CT Image IOD) and A.4 (MR
// Image IOD): Patient, General Study, General Series, Frame of Reference,
// General Image, Image Plane, Image Pixel, CT/MR Image. The volume's RAS+
// affine is written in DICOM's LPS+ frame (core/PatientFrame.h).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <unistd.h>

#include <glm/geometric.hpp>

#include "io/DicomToolkit.h"
#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/io/DicomSeriesReader.h"

#include <dcmtk/dcmdata/dcdatset.h>
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcuid.h>

namespace tessera {

namespace fs = std::filesystem;
using io_detail::conditionText;

namespace {

E_TransferSyntax transferSyntaxFor(const std::string& name, const std::string& what) {
  if (name == "little-endian-explicit") return EXS_LittleEndianExplicit;
  if (name == "jpeg-ls-lossless") return EXS_JPEGLSLossless;
  if (name == "rle") return EXS_RLELossless;
  if (name == "deflate") return EXS_DeflatedLittleEndianExplicit;
  throw InputError(what + ": transfer syntax '" + name +
                   "' is not one the writer offers (little-endian-explicit, jpeg-ls-lossless, "
                   "rle, deflate)");
}

// A Decimal String holds at most 16 characters (PS3.5 6.2): the most precise
// %g rendering that fits.
std::string decimalString(double v) {
  char buf[64];
  for (int precision = 17; precision >= 1; --precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, v);
    if (std::string(buf).size() <= 16) break;
  }
  return buf;
}

// The value a reader gets back from decimalString(v).
double asWritten(double v) {
  return std::stod(decimalString(v));
}

bool isValidUid(const std::string& uid) {
  if (uid.empty() || uid.size() > 64 || uid.front() == '.' || uid.back() == '.') return false;
  return std::all_of(uid.begin(), uid.end(),
                     [](char c) { return (c >= '0' && c <= '9') || c == '.'; });
}

std::string newUid(const char* root) {
  char buf[100];
  dcmGenerateUniqueIdentifier(buf, root);
  return buf;
}

// The Image Plane module of every slice (PS3.3 C.7.6.2), in LPS.
struct PlaneGeometry {
  glm::dvec3 row{1, 0, 0};            // IOP's first vector: direction of index x
  glm::dvec3 column{0, 1, 0};         // IOP's second vector: direction of index y
  glm::dvec3 normal{0, 0, 1};         // row x column
  std::vector<glm::dvec3> positions;  // IPP of each z-slice
  double spacingBetweenSlices = 1.0;  // along the normal
};

// IOP holds the index x and y directions. They are exactly the first two
// columns of the direction's nearest orthonormal frame unless x and y are
// not perpendicular (an in-plane shear, which IOP cannot hold): then those
// columns are written and the shear is lost. Positions come from the full
// affine (IPP_k = LPS(worldOf(0,0,k))), so the slice axis - including a
// gantry tilt's shear - and a left-handed z (which the reader recovers from
// Instance Number) are kept.
PlaneGeometry planeGeometry(const Volume& volume) {
  const glm::dmat3 lps = lpsToRas() * volume.direction();  // lpsToRas() is its own inverse
  PlaneGeometry p;
  p.row = glm::normalize(lps[0]);
  p.column = glm::normalize(lps[1]);
  if (std::abs(glm::dot(p.row, p.column)) > 1e-9) {
    const glm::dmat3 r = nearestOrthonormal(lps);
    p.row = r[0];
    p.column = r[1];
  }
  p.column = glm::normalize(p.column - glm::dot(p.column, p.row) * p.row);
  p.normal = glm::cross(p.row, p.column);
  for (int z = 0; z < volume.dims().z; ++z) {
    p.positions.push_back(lpsToRas() * volume.worldOf(glm::dvec3(0, 0, z)));
  }
  const glm::dvec3 step = lpsToRas() * volume.direction()[2] * volume.spacing().z;
  p.spacingBetweenSlices = std::abs(glm::dot(step, p.normal));
  return p;
}

// A direction cosine as written: round-off below 1e-12 becomes 0.
std::string cosineString(double v) {
  return decimalString(std::abs(v) < 1e-12 ? 0.0 : v);
}

std::string vectorString(const glm::dvec3& v, std::string (*format)(double)) {
  return format(v.x) + "\\" + format(v.y) + "\\" + format(v.z);
}

// How voxel values become stored pixels: stored = round((v - intercept) / slope).
struct PixelEncoding {
  int bits = 16;
  bool isSigned = false;
  double slope = 1.0;
  double intercept = 0.0;
  bool quantized = false;  // f32 values mapped onto 16-bit steps

  double minStored() const { return isSigned ? -std::ldexp(1.0, bits - 1) : 0.0; }
  double maxStored() const {
    return isSigned ? std::ldexp(1.0, bits - 1) - 1 : std::ldexp(1.0, bits) - 1;
  }
  double stored(double v) const { return std::round((v - intercept) / slope); }
};

PixelEncoding chooseEncoding(const Volume& volume, const DicomWriteOptions& o,
                             const std::string& what) {
  if (!std::isfinite(o.rescaleSlope) || o.rescaleSlope == 0.0 ||
      !std::isfinite(o.rescaleIntercept)) {
    throw InputError(what + ": rescale slope " + decimalString(o.rescaleSlope) + " / intercept " +
                     decimalString(o.rescaleIntercept) +
                     " cannot be written (slope must be finite and non-zero)");
  }
  PixelEncoding e;
  e.slope = asWritten(o.rescaleSlope);
  e.intercept = asWritten(o.rescaleIntercept);
  const ValueRange r = volume.valueRange();
  switch (volume.type()) {
    case ScalarType::U8:
      e.bits = 8;
      break;
    case ScalarType::U16:
      break;
    case ScalarType::I16:
      e.isSigned = true;
      break;
    case ScalarType::F32: {
      for (std::size_t i = 0; i < volume.voxelCount(); ++i) {
        if (!std::isfinite(volume.valueAtIndex(i))) {
          throw InputError(what + ": voxel " + std::to_string(i) +
                           " is not finite; DICOM pixels cannot hold it");
        }
      }
      const bool identity = o.rescaleSlope == 1.0 && o.rescaleIntercept == 0.0;
      bool integral = true;
      for (std::size_t i = 0; i < volume.voxelCount() && integral; ++i) {
        const double v = volume.valueAtIndex(i);
        integral = std::floor(v) == v;
      }
      if (identity && integral && r.min >= -32768 && r.max <= 32767) {
        e.isSigned = true;
      } else if (identity && integral && r.min >= 0 && r.max <= 65535) {
        e.isSigned = false;
      } else if (identity) {
        // Span [min, max] with the 65536 unsigned steps.
        e.quantized = true;
        e.intercept = asWritten(r.min);
        e.slope = r.max > r.min ? asWritten((r.max - r.min) / 65535.0) : 1.0;
        if (e.slope <= 0.0) e.slope = 1.0;
      } else {
        e.isSigned = e.stored(r.min) < 0 || e.stored(r.max) < 0;
      }
      break;
    }
  }
  if (e.quantized) return e;  // stored values are clamped to the steps below
  for (double v : {r.min, r.max}) {
    const double s = e.stored(v);
    if (s < e.minStored() || s > e.maxStored()) {
      throw InputError(what + ": value " + decimalString(v) + " with rescale slope " +
                       decimalString(e.slope) + " and intercept " + decimalString(e.intercept) +
                       " is stored as " + decimalString(s) + ", outside the " +
                       std::to_string(e.bits) + "-bit " + (e.isSigned ? "signed" : "unsigned") +
                       " range; choose another slope/intercept");
    }
  }
  return e;
}

void check(const OFCondition& c, const fs::path& file, const char* doing) {
  if (c.bad()) {
    throw Error(file.string() + ": " + doing + " failed (DCMTK: " + conditionText(c) + ")");
  }
}

struct SeriesAttributes {
  std::string sopClassUid;
  std::string modality;
  std::string studyUid;
  std::string seriesUid;
  std::string frameOfReferenceUid;
  std::string description;
};

void writeSlice(const Volume& volume, int z, const PixelEncoding& e, const SeriesAttributes& a,
                const PlaneGeometry& plane, E_TransferSyntax xfer, const fs::path& file) {
  DcmFileFormat ff;
  DcmDataset& ds = *ff.getDataset();
  auto put = [&](const DcmTagKey& tag, const std::string& value) {
    check(ds.putAndInsertString(tag, value.c_str()), file, "setting an attribute");
  };
  auto putU16 = [&](const DcmTagKey& tag, int value) {
    check(ds.putAndInsertUint16(tag, static_cast<Uint16>(value)), file, "setting an attribute");
  };
  const glm::ivec3 d = volume.dims();
  const glm::dvec3 sp = volume.spacing();

  put(DCM_SOPClassUID, a.sopClassUid);
  put(DCM_SOPInstanceUID, newUid(SITE_INSTANCE_UID_ROOT));
  // Type 2 attributes (present, may be empty) of the Patient and Study modules.
  for (const DcmTagKey& tag :
       {DCM_PatientName, DCM_PatientID, DCM_PatientBirthDate, DCM_PatientSex, DCM_StudyDate,
        DCM_StudyTime, DCM_ReferringPhysicianName, DCM_StudyID, DCM_AccessionNumber,
        DCM_Manufacturer, DCM_PositionReferenceIndicator}) {
    put(tag, "");
  }
  put(DCM_StudyInstanceUID, a.studyUid);
  put(DCM_SeriesInstanceUID, a.seriesUid);
  put(DCM_FrameOfReferenceUID, a.frameOfReferenceUid);
  put(DCM_Modality, a.modality);
  put(DCM_SeriesNumber, "1");
  put(DCM_SeriesDescription, a.description);
  put(DCM_ImageType, "DERIVED\\SECONDARY\\AXIAL");
  put(DCM_InstanceNumber, std::to_string(z + 1));
  if (a.modality == "CT") {
    put(DCM_KVP, "");
    put(DCM_AcquisitionNumber, "");
  } else {
    put(DCM_ScanningSequence, "RM");  // research mode: not from a scanner
    put(DCM_SequenceVariant, "NONE");
    for (const DcmTagKey& tag : {DCM_ScanOptions, DCM_MRAcquisitionType, DCM_RepetitionTime,
                                 DCM_EchoTime, DCM_EchoTrainLength}) {
      put(tag, "");
    }
  }

  const glm::dvec3 position = plane.positions[static_cast<std::size_t>(z)];
  put(DCM_ImagePositionPatient, vectorString(position, decimalString));
  put(DCM_ImageOrientationPatient,
      vectorString(plane.row, cosineString) + "\\" + vectorString(plane.column, cosineString));
  // Slice Location: the position along the normal, as scanners write it.
  put(DCM_SliceLocation, decimalString(glm::dot(position, plane.normal)));
  put(DCM_SpacingBetweenSlices, decimalString(plane.spacingBetweenSlices));
  put(DCM_SliceThickness, decimalString(plane.spacingBetweenSlices));
  // Pixel Spacing is (between rows, between columns) = (y, x).
  put(DCM_PixelSpacing, decimalString(sp.y) + "\\" + decimalString(sp.x));

  putU16(DCM_SamplesPerPixel, 1);
  put(DCM_PhotometricInterpretation, "MONOCHROME2");
  putU16(DCM_Rows, d.y);
  putU16(DCM_Columns, d.x);
  putU16(DCM_BitsAllocated, e.bits);
  putU16(DCM_BitsStored, e.bits);
  putU16(DCM_HighBit, e.bits - 1);
  putU16(DCM_PixelRepresentation, e.isSigned ? 1 : 0);
  put(DCM_RescaleIntercept, decimalString(e.intercept));
  put(DCM_RescaleSlope, decimalString(e.slope));

  const std::size_t n = static_cast<std::size_t>(d.x) * static_cast<std::size_t>(d.y);
  const std::size_t first = static_cast<std::size_t>(z) * n;
  auto storedAt = [&](std::size_t i) {
    const double s = e.stored(volume.valueAtIndex(first + i));
    return std::clamp(s, e.minStored(), e.maxStored());  // only quantized f32 can be outside
  };
  if (e.bits == 8) {
    std::vector<Uint8> pixels(n);
    for (std::size_t i = 0; i < n; ++i) pixels[i] = static_cast<Uint8>(storedAt(i));
    check(ds.putAndInsertUint8Array(DCM_PixelData, pixels.data(), static_cast<unsigned long>(n)),
          file, "setting pixel data");
  } else {
    std::vector<Uint16> pixels(n);
    for (std::size_t i = 0; i < n; ++i) {
      pixels[i] = static_cast<Uint16>(static_cast<std::int32_t>(storedAt(i)) & 0xffff);
    }
    check(ds.putAndInsertUint16Array(DCM_PixelData, pixels.data(), static_cast<unsigned long>(n)),
          file, "setting pixel data");
  }
  if (DcmXfer(xfer).isEncapsulated()) {
    check(ds.chooseRepresentation(xfer, nullptr), file,
          ("compressing to " + io_detail::transferSyntaxText(xfer)).c_str());
    if (!ds.canWriteXfer(xfer)) {
      throw Error(file.string() + ": DCMTK cannot write " + io_detail::transferSyntaxText(xfer));
    }
  }
  check(ff.saveFile(file.c_str(), xfer, EET_ExplicitLength), file, "writing the file");
}

std::vector<std::string> sliceFileNames(int slices, bool shuffle,
                                        const std::set<std::string>& taken) {
  std::vector<std::string> names;
  if (!shuffle) {
    char buf[32];
    for (int z = 0; z < slices; ++z) {
      std::snprintf(buf, sizeof buf, "slice_%04d.dcm", z);
      names.emplace_back(buf);
    }
    return names;
  }
  std::random_device rd;
  std::mt19937 rng(rd());
  std::set<std::string> used = taken;
  while (static_cast<int>(names.size()) < slices) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "IM%08X.dcm", static_cast<unsigned>(rng()));
    if (used.insert(buf).second) names.emplace_back(buf);
  }
  return names;
}

}  // namespace

void writeDicomSeries(const Volume& volume, const fs::path& folderIn,
                      const DicomWriteOptions& options) {
  io_detail::initDicomToolkit();
  fs::path folder = folderIn;
  if (!folder.has_filename()) folder = folder.parent_path();  // "out/" → "out"
  const std::string what = folder.string();
  if (!volume.hasData()) throw InputError(what + ": no voxels to write");
  const glm::ivec3 d = volume.dims();
  if (d.x > 65535 || d.y > 65535) {
    throw InputError(what + ": slices of " + std::to_string(d.x) + "x" + std::to_string(d.y) +
                     " pixels exceed DICOM's 65535 Rows/Columns");
  }
  const E_TransferSyntax xfer = transferSyntaxFor(options.transferSyntax, what);
  const PixelEncoding encoding = chooseEncoding(volume, options, what);
  const PlaneGeometry plane = planeGeometry(volume);

  SeriesAttributes a;
  a.modality = options.modality;
  if (a.modality.empty()) {
    a.modality =
        (encoding.slope != 1.0 || encoding.intercept != 0.0 || volume.type() == ScalarType::F32)
            ? "CT"
            : "MR";
  }
  if (a.modality == "CT") {
    a.sopClassUid = UID_CTImageStorage;
  } else if (a.modality == "MR") {
    a.sopClassUid = UID_MRImageStorage;
  } else {
    throw InputError(what + ": modality '" + a.modality +
                     "' is not one the writer offers (CT, MR)");
  }
  if (!options.seriesInstanceUid.empty() && !isValidUid(options.seriesInstanceUid)) {
    throw InputError(what + ": '" + options.seriesInstanceUid +
                     "' is not a DICOM UID (digits and dots, at most 64 characters)");
  }
  a.seriesUid =
      options.seriesInstanceUid.empty() ? newUid(SITE_SERIES_UID_ROOT) : options.seriesInstanceUid;
  a.studyUid = newUid(SITE_STUDY_UID_ROOT);
  a.frameOfReferenceUid = newUid(SITE_INSTANCE_UID_ROOT);
  a.description = options.seriesDescription;

  std::error_code ec;
  const bool existed = fs::exists(folder, ec);
  if (existed && !fs::is_directory(folder, ec)) {
    throw InputError(what + ": exists and is not a directory");
  }
  std::set<std::string> taken;
  if (existed) {
    for (const auto& entry : fs::directory_iterator(folder, ec)) {
      taken.insert(entry.path().filename().string());
    }
  }
  const std::vector<std::string> names = sliceFileNames(d.z, options.shuffleFileNames, taken);
  for (const auto& n : names) {
    if (taken.count(n) != 0) {
      throw InputError(what + ": " + n +
                       " already exists; write the series into another folder (or use "
                       "shuffled names)");
    }
  }

  // A hidden sibling (new folder) or child (existing folder, which the
  // non-recursive reader does not look into) holds the files until done.
  const fs::path parent = folder.parent_path().empty() ? fs::path(".") : folder.parent_path();
  fs::create_directories(parent, ec);
  std::random_device rd;
  const std::string tag = std::to_string(::getpid()) + "-" + std::to_string(rd());
  const fs::path temp = existed ? folder / (".tessera-partial-" + tag)
                                : parent / ("." + folder.filename().string() + ".partial-" + tag);
  fs::create_directories(temp, ec);
  if (ec) throw Error(temp.string() + ": cannot create the temporary folder: " + ec.message());
  try {
    for (int z = 0; z < d.z; ++z) {
      writeSlice(volume, z, encoding, a, plane, xfer, temp / names[static_cast<std::size_t>(z)]);
    }
    if (!existed) {
      fs::rename(temp, folder, ec);
      if (!ec) return;
      // Someone created the folder meanwhile: move the files in as below.
      fs::create_directories(folder);
    }
    std::vector<fs::path> moved;
    try {
      for (const auto& n : names) {
        if (fs::exists(folder / n)) throw Error((folder / n).string() + ": appeared meanwhile");
        fs::rename(temp / n, folder / n);
        moved.push_back(folder / n);
      }
    } catch (...) {
      for (const auto& m : moved) fs::remove(m, ec);
      throw;
    }
    fs::remove_all(temp, ec);
  } catch (...) {
    fs::remove_all(temp, ec);
    throw;
  }
}

double dicomQuantisationError(const Volume& volume, const DicomWriteOptions& options) {
  io_detail::initDicomToolkit();
  if (!volume.hasData()) return 0.0;
  const PixelEncoding e = chooseEncoding(volume, options, "volume");
  // What the reader computes: stored * slope + intercept, as f32 unless
  // slope and intercept are integers (then the values stay integers).
  const bool toFloat = std::floor(e.slope) != e.slope || std::floor(e.intercept) != e.intercept;
  double worst = 0.0;
  for (std::size_t i = 0; i < volume.voxelCount(); ++i) {
    const double v = volume.valueAtIndex(i);
    const double stored = std::clamp(e.stored(v), e.minStored(), e.maxStored());
    double back = stored * e.slope + e.intercept;
    if (toFloat) back = static_cast<float>(back);
    worst = std::max(worst, std::abs(back - v));
  }
  return worst;
}

}  // namespace tessera
